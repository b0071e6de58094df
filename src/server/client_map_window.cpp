#include "server/client_map_window.h"

#include <algorithm>
#include <cmath>
#include <unordered_set>

#include "map/map_replication.h"

namespace edgeslam {

std::vector<KeyFrame*> keyFrameNeighbourhood(const Map& map, KeyFrame* centre, std::size_t count,
                                             std::size_t recent) {
  std::vector<KeyFrame*> chosen;
  if (centre == nullptr || centre->isBad() || count == 0) return chosen;
  std::unordered_set<KeyFrameId> in;
  const auto choose = [&](KeyFrame* kf) {
    if (chosen.size() < count && !kf->isBad() && in.insert(kf->id()).second) chosen.push_back(kf);
  };
  choose(centre);
  if (recent > 0) {
    const std::vector<KeyFrame*> all = map.keyFrames();  // by id: the newest last
    std::size_t taken = 0;
    // The centre's own client's: in a map several clients write, the others' newest keyframes
    // are far away (their ids have another top byte).
    for (auto it = all.rbegin(); it != all.rend() && taken < recent; ++it) {
      if ((*it)->isBad() || idOrigin((*it)->id()) != idOrigin(centre->id())) continue;
      choose(*it);
      ++taken;
    }
  }
  // Breadth first over the covisibility graph, each keyframe's links strongest first.
  for (std::size_t next = 0; next < chosen.size() && chosen.size() < count; ++next) {
    const KeyFrame* kf = chosen[next];
    for (KeyFrame* other : kf->bestCovisibles(kf->connections().size())) choose(other);
  }
  return chosen;
}

ClientMapWindow::ClientMapWindow(ClientMapWindowOptions options) : options_(options) {
  options_.keep_factor = std::max(1.0, options_.keep_factor);
  options_.recent_share = std::clamp(options_.recent_share, 0.0, 1.0);
}

std::size_t ClientMapWindow::keepSize() const {
  return static_cast<std::size_t>(
      std::ceil(static_cast<double>(options_.keyframes) * options_.keep_factor));
}

std::size_t ClientMapWindow::recentCount() const {
  return static_cast<std::size_t>(
      std::floor(static_cast<double>(options_.keyframes) * options_.recent_share));
}

bool ClientMapWindow::seenByHeld(const MapPoint& point) const {
  for (const auto& [id, obs] : point.observations()) {
    if (held_.contains(id)) return true;
  }
  return false;
}

void ClientMapWindow::shape(const Map& map, KeyFrame* centre, MapSlice& slice) {
  if (!bounded()) return;
  for (KeyFrameId id : slice.keyframes_erased) held_.erase(id);

  std::vector<KeyFrame*> entering;
  if (centre != nullptr && !centre->isBad()) {
    const std::vector<KeyFrame*> keep =
        keyFrameNeighbourhood(map, centre, keepSize(), recentCount());
    std::unordered_set<KeyFrameId> kept;
    for (KeyFrame* kf : keep) kept.insert(kf->id());
    for (auto it = held_.begin(); it != held_.end();) {
      // Keyframes newer than the centre are still on their way through mapping: never evicted.
      const bool newer = idOrigin(*it) == idOrigin(centre->id()) && *it > centre->id();
      if (!kept.contains(*it) && !newer) {
        // The edge no longer has it (culled): the client erases it through keyframes_erased.
        if (map.keyFrame(*it) != nullptr) slice.keyframes_evicted.push_back(*it);
        it = held_.erase(it);
      } else {
        ++it;
      }
    }
    const std::size_t window = std::min(options_.keyframes, keep.size());
    for (std::size_t i = 0; i < window && entering.size() < options_.max_entering_per_slice; ++i) {
      if (!held_.contains(keep[i]->id())) entering.push_back(keep[i]);
    }
  }

  // Points the client lacks among those the entering keyframes see: the ones no keyframe it kept
  // holding sees.
  std::unordered_set<MapPointId> listed;
  for (const MapPointRecord& r : slice.points_upserted) listed.insert(r.id);
  std::vector<const MapPoint*> entering_points;
  for (KeyFrame* kf : entering) {
    for (MapPoint* p : kf->goodPoints()) {
      if (!seenByHeld(*p) && listed.insert(p->id()).second) entering_points.push_back(p);
    }
  }
  for (KeyFrame* kf : entering) {
    slice.keyframes.push_back(keyFrameRecord(*kf));
    held_.insert(kf->id());
  }

  std::vector<MapPointRecord> points;
  points.reserve(slice.points_upserted.size() + entering_points.size());
  for (MapPointRecord& r : slice.points_upserted) {
    const MapPoint* p = map.mapPoint(r.id);
    if (p != nullptr && seenByHeld(*p)) points.push_back(std::move(r));
  }
  for (const MapPoint* p : entering_points) points.push_back(mapPointRecord(*p));
  slice.points_upserted = std::move(points);
  std::erase_if(slice.point_positions,
                [&](const PointPositionRecord& r) REQUIRES(map.updateMutex()) {
                  const MapPoint* p = map.mapPoint(r.id);
                  return p == nullptr || !seenByHeld(*p);
                });
}

}  // namespace edgeslam
