#include "modes/localization_slam.h"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <stdexcept>

#include "store/stored_map_loader.h"
#include "util/timing_stats.h"

namespace edgeslam {
namespace {

SlamOptions localizationOptions(SlamOptions options) {
  options.tracker.localization_only = true;
  options.refine_intrinsics = false;  // the map is not re-solved
  return options;
}

void checkSessionServes(const StoredSession& session, const PinholeCamera& camera, Sensor sensor) {
  if (session.info.sensor != sensor) {
    throw std::invalid_argument(
        fmt::format("the stored map was made with a {} sensor; this run has a {} one (--sensor)",
                    toString(session.info.sensor), toString(sensor)));
  }
  const PinholeCamera& stored = session.info.camera;
  if (stored.width() != camera.width() || stored.height() != camera.height()) {
    throw std::invalid_argument(
        fmt::format("the stored map was made with {}x{} images; this dataset has {}x{}",
                    stored.width(), stored.height(), camera.width(), camera.height()));
  }
}

}  // namespace

LocalizationSlam::LocalizationSlam(const PinholeCamera& camera, SlamOptions options,
                                   const StoredSession& session)
    : TrackingSlam(camera, localizationOptions(std::move(options)), 0) {
  checkSessionServes(session, camera_, options_.sensor);
  if (options_.tracker.vocabulary == nullptr || options_.tracker.vocabulary->empty()) {
    throw std::invalid_argument(
        "localisation in a stored map needs a vocabulary (not --vocab none)");
  }
  Stopwatch timer;
  loadStoredSession(session, map_);  // takes the map's mutex itself
  stored_keyframes_ = keyFrameCount();
  startTracking(nullptr);
  tracker_->localizeInMap();
  spdlog::info("localising in a stored map of {} keyframes and {} points ({:.0f} ms to load)",
               stored_keyframes_, mapPointCount(), timer.elapsedMs());
}

SlamCounters LocalizationSlam::counters() const {
  SlamCounters out;
  addClientCounters(out);
  return out;
}

}  // namespace edgeslam
