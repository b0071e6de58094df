#pragma once
// `run --viewer PORT`: the web viewer beside a run. Started before the first frame (so a bad port
// ends the run before it begins), fed after every frame, and, with --viewer-linger, kept up on the
// final map after the run until Ctrl-C or the timeout.
#include <memory>
#include <optional>
#include <string>

#include "modes/slam_system.h"
#include "viz/live_view.h"
#include "viz/viewer_server.h"

namespace edgeslam::cli {

class RunViewer {
 public:
  // Throws viz::ViewerError when the port cannot be served.
  RunViewer(const std::string& host, int port);
  ~RunViewer();
  RunViewer(const RunViewer&) = delete;
  RunViewer& operator=(const RunViewer&) = delete;

  int port() const { return server_->port(); }
  viz::LiveView& view() { return view_; }

  // Samples `slam`'s map for the page until the returned guard goes (declare it after `slam`'s
  // owner, so that sampling ends before the system does).
  class Attachment {
   public:
    explicit Attachment(viz::LiveView* view) : view_(view) {}
    ~Attachment();
    Attachment(const Attachment&) = delete;
    Attachment& operator=(const Attachment&) = delete;

   private:
    viz::LiveView* view_;
  };
  [[nodiscard]] std::unique_ptr<Attachment> attach(const SlamSystem& slam);

  // After a frame: while a page shows the camera image (at most a few times a second), the frame
  // with its features by state (on the map, new: from the tracking result; culled: the semantic
  // frame's) and movable mask. `always`: whether or not a page asks (the run's last frame, for a
  // page opened while the viewer lingers).
  void publishImage(const cv::Mat& image, const TrackResult& tracked, const SemanticFrame* semantic,
                    bool always = false);

  // Marks the run finished; with `seconds` > 0 keeps serving until then or until SIGINT.
  void finish(double linger_seconds);

 private:
  viz::LiveView view_;
  std::unique_ptr<viz::ViewerServer> server_;
};

}  // namespace edgeslam::cli
