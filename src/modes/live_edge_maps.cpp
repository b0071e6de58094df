#include "modes/live_edge_maps.h"

#include <fmt/format.h>

namespace edgeslam {

LiveEdgeMap::~LiveEdgeMap() {
  if (session) session->stop();
  if (store_writer) store_writer->stop();
}

std::optional<std::string> whyCannotJoin(const SessionConfig& made_by,
                                         const SessionConfig& joining) {
  if (joining.sensor != made_by.sensor) {
    return fmt::format("it is mapped with a {} sensor and this client has a {} one",
                       toString(made_by.sensor), toString(joining.sensor));
  }
  const CameraIntrinsics& a = made_by.camera.intrinsics();
  const CameraIntrinsics& b = joining.camera.intrinsics();
  if (made_by.camera.width() != joining.camera.width() ||
      made_by.camera.height() != joining.camera.height() || a.fx != b.fx || a.fy != b.fy ||
      a.cx != b.cx || a.cy != b.cy) {
    return fmt::format(
        "it is mapped with another camera ({}x{}, fx {:.1f} fy {:.1f} cx {:.1f} cy {:.1f}; this "
        "client's: {}x{}, fx {:.1f} fy {:.1f} cx {:.1f} cy {:.1f})",
        made_by.camera.width(), made_by.camera.height(), a.fx, a.fy, a.cx, a.cy,
        joining.camera.width(), joining.camera.height(), b.fx, b.fy, b.cx, b.cy);
  }
  const SessionSettings& s = made_by.settings;
  const SessionSettings& t = joining.settings;
  if (s.pyramid_levels != t.pyramid_levels || s.scale_factor != t.scale_factor) {
    return fmt::format("its features have {} levels, scale {:.2f}; this client's {} levels, {:.2f}",
                       s.pyramid_levels, s.scale_factor, t.pyramid_levels, t.scale_factor);
  }
  if (s.semantic != t.semantic) {
    return fmt::format("it is mapped {} semantic culling and this client asks {} it",
                       s.semantic ? "with" : "without", t.semantic ? "for" : "not for");
  }
  if (t.client_map_keyframes <= 0) {
    return std::string(
        "this client holds the whole map (client map keyframes 0); a client joining a map others "
        "write needs a bounded one");
  }
  return std::nullopt;
}

std::shared_ptr<LiveEdgeMap> LiveEdgeMaps::findOrMake(
    const std::string& name, const std::function<std::shared_ptr<LiveEdgeMap>()>& make,
    bool& joined) {
  MutexLock lock(mutex_);
  if (const auto it = maps_.find(name); it != maps_.end()) {
    if (std::shared_ptr<LiveEdgeMap> live = it->second.lock()) {
      joined = true;
      return live;
    }
    maps_.erase(it);
  }
  std::shared_ptr<LiveEdgeMap> made = make();
  joined = false;
  if (made) maps_[name] = made;
  return made;
}

}  // namespace edgeslam
