#include "mapping/movable_points.h"

#include <opencv2/imgproc.hpp>

#include "map/keyframe.h"
#include "map/map_point.h"

namespace edgeslam {

std::size_t eraseMovablePoints(Map& map, KeyFrame& keyframe, const cv::Mat1b& labels,
                               int erode_px) {
  if (labels.empty() || keyframe.isBad() || cv::countNonZero(labels) == 0) return 0;
  // A fresh matrix: writing into a header sharing the caller's labels would change them.
  cv::Mat1b inside;
  if (erode_px > 0) {
    cv::erode(
        labels > 0, inside,
        cv::getStructuringElement(cv::MORPH_RECT, cv::Size(2 * erode_px + 1, 2 * erode_px + 1)));
  } else {
    inside = labels;
  }
  const FrameFeatures& features = keyframe.features();
  std::vector<MapPoint*> movable;
  const std::vector<MapPoint*>& points = keyframe.points();
  for (std::size_t i = 0; i < points.size(); ++i) {
    MapPoint* p = points[i];
    if (p == nullptr || p->isBad()) continue;
    const cv::Point2f& pt = features.keypoints[i].pt;
    const int x = cvFloor(pt.x), y = cvFloor(pt.y);
    if (x < 0 || y < 0 || x >= inside.cols || y >= inside.rows || inside(y, x) == 0) continue;
    movable.push_back(p);
  }
  for (MapPoint* p : movable) map.erasePoint(p);
  return movable.size();
}

}  // namespace edgeslam
