#include "viz/view_snapshot.h"

#include <cmath>

namespace edgeslam::viz {
namespace {

// `value` to the nearest 1/scale; a non-finite value gives 0, and + 0.0 avoids "-0.0" in the text.
double rounded(double value, double scale) {
  return std::isfinite(value) ? std::round(value * scale) / scale + 0.0 : 0.0;
}

double millimetres(double metres) {
  return rounded(metres, 1000.0);
}

nlohmann::json statusJson(const RunStatus& s) {
  return {{"frame", s.frame},
          {"frames_total", s.frames_total},
          {"fps", rounded(s.fps, 10.0)},
          {"state", s.state},
          {"tracked_points", s.tracked_points},
          {"keyframes", s.keyframes},
          {"map_points", s.map_points},
          {"client_ms", rounded(s.client_ms, 100.0)},
          {"e2e_ms", rounded(s.e2e_ms, 100.0)},
          {"uplink_bytes", s.uplink_bytes},
          {"downlink_bytes", s.downlink_bytes},
          {"mode", s.mode},
          {"sensor", s.sensor},
          {"link", s.link},
          {"adaptation_row", s.adaptation_row},
          {"instruction", s.instruction},
          {"checkpoint", s.checkpoint},
          {"finished", s.finished}};
}

}  // namespace

nlohmann::json flatPositions(const std::vector<Eigen::Vector3d>& positions) {
  nlohmann::json out = nlohmann::json::array();
  out.get_ref<nlohmann::json::array_t&>().reserve(positions.size() * 3);
  for (const Eigen::Vector3d& p : positions) {
    if (!p.allFinite()) continue;
    out.push_back(millimetres(p.x()));
    out.push_back(millimetres(p.y()));
    out.push_back(millimetres(p.z()));
  }
  return out;
}

std::optional<nlohmann::json> poseJson(const ViewPose& pose) {
  const Eigen::Quaterniond& q = pose.orientation;
  if (!pose.position.allFinite() || !q.coeffs().allFinite()) return std::nullopt;
  return nlohmann::json{
      {"position",
       {millimetres(pose.position.x()), millimetres(pose.position.y()),
        millimetres(pose.position.z())}},
      {"orientation",
       {rounded(q.x(), 1e4), rounded(q.y(), 1e4), rounded(q.z(), 1e4), rounded(q.w(), 1e4)}}};
}

nlohmann::json toJson(const ViewSnapshot& snapshot) {
  nlohmann::json keyframes = nlohmann::json::array();
  for (const ViewPose& kf : snapshot.keyframes) {
    if (auto pose = poseJson(kf)) keyframes.push_back(std::move(*pose));
  }
  std::optional<nlohmann::json> camera;
  if (snapshot.camera) camera = poseJson(*snapshot.camera);
  return {{"view", "mobile"},
          {"version", snapshot.version},
          {"status", statusJson(snapshot.status)},
          {"camera", camera ? *camera : nlohmann::json(nullptr)},
          {"trajectory", flatPositions(snapshot.trajectory)},
          {"ground_truth", flatPositions(snapshot.ground_truth)},
          {"keyframes", std::move(keyframes)},
          {"points", flatPositions(snapshot.points)},
          {"points_total", snapshot.points_total},
          {"route", flatPositions(snapshot.route)}};
}

}  // namespace edgeslam::viz
