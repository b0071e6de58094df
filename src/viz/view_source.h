#pragma once
// What the viewer's HTTP server shows: a run's LiveView (the mobile view) or an edge server's
// EdgeView. Called from the viewer's threads.
#include <optional>
#include <string>

#include "viz/frame_image_slot.h"

namespace edgeslam::viz {

class ViewSource {
 public:
  virtual ~ViewSource() = default;
  // The snapshot as JSON (docs/viewer.md); may be a cached encoding shared by every page.
  virtual std::string snapshotJson() = 0;
  // The camera image, where the view has one.
  virtual FrameImageSlot* images() { return nullptr; }
  // A map the view can show on request (the edge view's stored maps) as JSON; nullopt: none.
  virtual std::optional<std::string> storedMapJson(const std::string& /*name*/) {
    return std::nullopt;
  }
};

}  // namespace edgeslam::viz
