#include "eval/alignment.h"

#include <fmt/format.h>

#include <Eigen/Geometry>
#include <cmath>

#include "eval/eval_error.h"

namespace edgeslam {
namespace {

Eigen::Matrix3Xd toMatrix(const std::vector<Eigen::Vector3d>& points) {
  Eigen::Matrix3Xd m(3, static_cast<Eigen::Index>(points.size()));
  for (std::size_t i = 0; i < points.size(); ++i) m.col(static_cast<Eigen::Index>(i)) = points[i];
  return m;
}

}  // namespace

std::string toString(AlignMode mode) {
  switch (mode) {
    case AlignMode::kNone:
      return "none";
    case AlignMode::kSe3:
      return "se3";
    case AlignMode::kSim3:
      return "sim3";
  }
  return "unknown";
}

AlignMode parseAlignMode(const std::string& name) {
  if (name == "none") return AlignMode::kNone;
  if (name == "se3") return AlignMode::kSe3;
  if (name == "sim3") return AlignMode::kSim3;
  throw EvalError(fmt::format("unknown alignment '{}' (expected none, se3 or sim3)", name));
}

std::size_t minimumPairsForAlignment(AlignMode mode) {
  return mode == AlignMode::kNone ? 1 : 3;
}

Sim3d alignPositions(const std::vector<Eigen::Vector3d>& est,
                     const std::vector<Eigen::Vector3d>& gt, AlignMode mode) {
  if (est.size() != gt.size()) {
    throw EvalError(
        fmt::format("alignment needs as many estimated positions ({}) as ground-truth "
                    "positions ({})",
                    est.size(), gt.size()));
  }
  const std::size_t needed = minimumPairsForAlignment(mode);
  if (est.size() < needed) {
    throw EvalError(fmt::format("{} alignment needs at least {} pose pairs, got {}", toString(mode),
                                needed, est.size()));
  }
  if (mode == AlignMode::kNone) return Sim3d::identity();

  const Eigen::Matrix3Xd source = toMatrix(est);
  const Eigen::Matrix3Xd target = toMatrix(gt);
  const Eigen::Vector3d mean = source.rowwise().mean();
  const double spread = (source.colwise() - mean).squaredNorm();
  if (!(spread > 1e-18)) {
    throw EvalError(
        fmt::format("cannot align: all {} estimated positions are the same point", est.size()));
  }
  const Eigen::Matrix4d t = Eigen::umeyama(source, target, mode == AlignMode::kSim3);
  const Eigen::Matrix3d scaled_rotation = t.topLeftCorner<3, 3>();
  // Umeyama returns s R; for se3 s is 1 by construction, keep it exactly 1.
  const double scale = mode == AlignMode::kSim3 ? std::cbrt(scaled_rotation.determinant()) : 1.0;
  if (!(scale > 0.0) || !std::isfinite(scale)) {
    throw EvalError(fmt::format("alignment failed (scale {})", scale));
  }
  const Eigen::Matrix3d rotation = scaled_rotation / scale;
  return {scale, Eigen::Quaterniond(rotation).normalized(), t.topRightCorner<3, 1>()};
}

std::vector<Eigen::Vector3d> gtPositions(const PosePairs& pairs) {
  std::vector<Eigen::Vector3d> out;
  out.reserve(pairs.size());
  for (const PosePair& p : pairs) out.push_back(p.gt.translation());
  return out;
}

std::vector<Eigen::Vector3d> estPositions(const PosePairs& pairs) {
  std::vector<Eigen::Vector3d> out;
  out.reserve(pairs.size());
  for (const PosePair& p : pairs) out.push_back(p.est.translation());
  return out;
}

Sim3d alignPairs(const PosePairs& pairs, AlignMode mode) {
  return alignPositions(estPositions(pairs), gtPositions(pairs), mode);
}

}  // namespace edgeslam
