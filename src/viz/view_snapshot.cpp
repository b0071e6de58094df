#include "viz/view_snapshot.h"

#include <cmath>

namespace edgeslam::viz {
namespace {

double finiteOrZero(double value) {
  return std::isfinite(value) ? value : 0.0;
}

double millimetres(double metres) {
  return std::round(metres * 1000.0) / 1000.0 + 0.0;  // + 0.0: no "-0.0" in the text
}

double fourDecimals(double value) {
  return std::round(value * 1e4) / 1e4 + 0.0;
}

bool isFinite(const Eigen::Vector3d& v) {
  return v.allFinite();
}

nlohmann::json flatPositions(const std::vector<Eigen::Vector3d>& positions) {
  nlohmann::json out = nlohmann::json::array();
  out.get_ref<nlohmann::json::array_t&>().reserve(positions.size() * 3);
  for (const Eigen::Vector3d& p : positions) {
    if (!isFinite(p)) continue;
    out.push_back(millimetres(p.x()));
    out.push_back(millimetres(p.y()));
    out.push_back(millimetres(p.z()));
  }
  return out;
}

std::optional<nlohmann::json> poseJson(const ViewPose& pose) {
  const Eigen::Quaterniond& q = pose.orientation;
  if (!isFinite(pose.position) || !q.coeffs().allFinite()) return std::nullopt;
  return nlohmann::json{
      {"position",
       {millimetres(pose.position.x()), millimetres(pose.position.y()),
        millimetres(pose.position.z())}},
      {"orientation",
       {fourDecimals(q.x()), fourDecimals(q.y()), fourDecimals(q.z()), fourDecimals(q.w())}}};
}

nlohmann::json statusJson(const RunStatus& s) {
  return {{"frame", s.frame},
          {"frames_total", s.frames_total},
          {"fps", std::round(finiteOrZero(s.fps) * 10.0) / 10.0},
          {"state", s.state},
          {"tracked_points", s.tracked_points},
          {"keyframes", s.keyframes},
          {"map_points", s.map_points},
          {"client_ms", std::round(finiteOrZero(s.client_ms) * 100.0) / 100.0},
          {"uplink_bytes", s.uplink_bytes},
          {"downlink_bytes", s.downlink_bytes},
          {"mode", s.mode},
          {"sensor", s.sensor},
          {"finished", s.finished}};
}

}  // namespace

nlohmann::json toJson(const ViewSnapshot& snapshot) {
  nlohmann::json keyframes = nlohmann::json::array();
  for (const ViewPose& kf : snapshot.keyframes) {
    if (auto pose = poseJson(kf)) keyframes.push_back(std::move(*pose));
  }
  std::optional<nlohmann::json> camera;
  if (snapshot.camera) camera = poseJson(*snapshot.camera);
  return {{"version", snapshot.version},
          {"status", statusJson(snapshot.status)},
          {"camera", camera ? *camera : nlohmann::json(nullptr)},
          {"trajectory", flatPositions(snapshot.trajectory)},
          {"ground_truth", flatPositions(snapshot.ground_truth)},
          {"keyframes", std::move(keyframes)},
          {"points", flatPositions(snapshot.points)},
          {"points_total", snapshot.points_total}};
}

}  // namespace edgeslam::viz
