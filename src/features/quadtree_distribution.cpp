#include "features/quadtree_distribution.h"

#include <algorithm>
#include <cmath>
#include <queue>

namespace edgeslam {
namespace {

// What the splitting looks at, packed so that partitioning moves 16 bytes per keypoint instead of
// chasing indices into the 28-byte cv::KeyPoint array.
struct Point {
  float x, y, response;
  int index;  // into the input keypoints
};

struct Node {
  float x0, y0, x1, y1;
  int begin, end;  // range in the shared point array
  float area() const { return (x1 - x0) * (y1 - y0); }
  int count() const { return end - begin; }
};

struct SplitFirst {
  bool operator()(const Node& a, const Node& b) const {
    if (a.area() != b.area()) return a.area() < b.area();
    return a.count() < b.count();
  }
};

}  // namespace

std::vector<cv::KeyPoint> distributeQuadtree(const std::vector<cv::KeyPoint>& keypoints,
                                             const cv::Rect2f& region, int target) {
  if (target <= 0) return {};
  if (static_cast<int>(keypoints.size()) <= target) return keypoints;

  std::vector<Point> points(keypoints.size());

  std::priority_queue<Node, std::vector<Node>, SplitFirst> splittable;
  std::vector<Node> done;  // nodes that cannot or need not be split
  auto addNode = [&](const Node& node) {
    if (node.count() == 0) return;
    // Below a pixel, keypoints cannot be told apart spatially any more.
    if (node.count() == 1 || node.x1 - node.x0 < 1.f || node.y1 - node.y0 < 1.f) {
      done.push_back(node);
    } else {
      splittable.push(node);
    }
  };

  const int roots = std::max(1, static_cast<int>(std::lround(region.width / region.height)));
  const float root_width = region.width / static_cast<float>(roots);
  {
    // Group the indices by root column (a counting sort).
    std::vector<int> column(keypoints.size());
    std::vector<int> start(roots + 1, 0);
    for (std::size_t i = 0; i < keypoints.size(); ++i) {
      const float x = keypoints[i].pt.x - region.x;
      column[i] = std::clamp(static_cast<int>(x / root_width), 0, roots - 1);
      ++start[column[i] + 1];
    }
    for (int c = 0; c < roots; ++c) start[c + 1] += start[c];
    std::vector<int> fill(start.begin(), start.end() - 1);
    for (int i = 0; i < static_cast<int>(keypoints.size()); ++i) {
      const cv::KeyPoint& kp = keypoints[i];
      points[fill[column[i]]++] = {kp.pt.x, kp.pt.y, kp.response, i};
    }
    for (int c = 0; c < roots; ++c) {
      const float x0 = region.x + static_cast<float>(c) * root_width;
      addNode({x0, region.y, x0 + root_width, region.y + region.height, start[c], start[c + 1]});
    }
  }

  while (!splittable.empty() && static_cast<int>(splittable.size() + done.size()) < target) {
    const Node node = splittable.top();
    splittable.pop();
    const float mx = 0.5f * (node.x0 + node.x1), my = 0.5f * (node.y0 + node.y1);
    auto first = points.begin() + node.begin, last = points.begin() + node.end;
    auto above = [my](const Point& p) { return p.y < my; };
    auto left = [mx](const Point& p) { return p.x < mx; };
    const auto top_end = std::partition(first, last, above);
    const auto top_left_end = std::partition(first, top_end, left);
    const auto bottom_left_end = std::partition(top_end, last, left);
    const int t = static_cast<int>(top_end - points.begin());
    const int tl = static_cast<int>(top_left_end - points.begin());
    const int bl = static_cast<int>(bottom_left_end - points.begin());
    addNode({node.x0, node.y0, mx, my, node.begin, tl});
    addNode({mx, node.y0, node.x1, my, tl, t});
    addNode({node.x0, my, mx, node.y1, t, bl});
    addNode({mx, my, node.x1, node.y1, bl, node.end});
  }
  while (!splittable.empty()) {
    done.push_back(splittable.top());
    splittable.pop();
  }

  std::vector<cv::KeyPoint> selected;
  selected.reserve(done.size());
  for (const Node& node : done) {
    const Point* best = &points[node.begin];
    for (int k = node.begin + 1; k < node.end; ++k) {
      if (points[k].response > best->response) best = &points[k];
    }
    selected.push_back(keypoints[best->index]);
  }
  // The last split can overshoot by up to three nodes: drop the weakest.
  if (static_cast<int>(selected.size()) > target) {
    std::nth_element(
        selected.begin(), selected.begin() + target, selected.end(),
        [](const cv::KeyPoint& a, const cv::KeyPoint& b) { return a.response > b.response; });
    selected.resize(target);
  }
  return selected;
}

}  // namespace edgeslam
