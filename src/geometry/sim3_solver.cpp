#include "geometry/sim3_solver.h"

#include <fmt/format.h>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "geometry/ransac_sampling.h"

namespace edgeslam {
namespace {

// Relative spread below which three or more points are treated as collinear.
constexpr double kCollinearTolerance = 1e-10;

bool isDegenerate(const Eigen::Matrix3Xd& points) {
  const Eigen::Vector3d mean = points.rowwise().mean();
  const Eigen::Matrix3Xd centered = points.colwise() - mean;
  const Eigen::Matrix3d cov = centered * centered.transpose();
  const Eigen::Vector3d ev = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(cov).eigenvalues();
  return !(ev(2) > 0.0) || !(ev(1) > kCollinearTolerance * ev(2));
}

std::optional<Sim3d> fitSimilarity(const Eigen::Matrix3Xd& p1, const Eigen::Matrix3Xd& p2,
                                   bool fix_scale) {
  if (p1.cols() < 3 || isDegenerate(p1) || isDegenerate(p2)) return std::nullopt;
  const Eigen::Matrix4d T = Eigen::umeyama(p2, p1, !fix_scale);
  if (!T.allFinite()) return std::nullopt;
  const Eigen::Matrix3d sR = T.topLeftCorner<3, 3>();
  const double scale = fix_scale ? 1.0 : std::cbrt(sR.determinant());
  if (!(scale > 0.0)) return std::nullopt;
  return Sim3d(scale, Eigen::Quaterniond(Eigen::Matrix3d(sR / scale)), T.topRightCorner<3, 1>());
}

void validate(std::span<const Sim3Match> matches, const Eigen::Matrix3d& K1,
              const Eigen::Matrix3d& K2, const Sim3SolverOptions& o) {
  auto require = [](bool ok, const std::string& what) {
    if (!ok) throw std::invalid_argument("solveSim3Ransac: " + what);
  };
  for (size_t i = 0; i < matches.size(); ++i) {
    const Sim3Match& m = matches[i];
    require(m.point1.allFinite() && m.point2.allFinite() && m.pixel1.allFinite() &&
                m.pixel2.allFinite(),
            fmt::format("match {} has a non-finite coordinate", i));
    require(m.sigma1_px > 0.0 && m.sigma2_px > 0.0,
            fmt::format("match {} has a non-positive sigma", i));
  }
  for (const Eigen::Matrix3d* K : {&K1, &K2}) {
    require(K->allFinite() && (*K)(0, 0) > 0.0 && (*K)(1, 1) > 0.0 && (*K)(2, 2) == 1.0,
            "K must be a calibration matrix with positive focal lengths");
  }
  require(o.max_iterations > 0, "max_iterations must be positive");
  require(o.confidence > 0.0 && o.confidence < 1.0, "confidence must be in (0, 1)");
  require(o.chi2_threshold > 0.0, "chi2_threshold must be positive");
  require(o.min_inliers >= 3, "min_inliers must be >= 3");
}

bool reprojects(const Eigen::Matrix3d& K, const Eigen::Vector3d& point_camera,
                const Eigen::Vector2d& pixel, double sigma_px, double chi2_threshold) {
  if (!(point_camera.z() > 0.0)) return false;
  const double e2 = ((K * point_camera).hnormalized() - pixel).squaredNorm();
  return e2 < chi2_threshold * sigma_px * sigma_px;
}

int markInliers(const Sim3d& S12, std::span<const Sim3Match> matches, const Eigen::Matrix3d& K1,
                const Eigen::Matrix3d& K2, double chi2_threshold, std::vector<char>& inliers) {
  const Sim3d S21 = S12.inverse();
  inliers.assign(matches.size(), 0);
  int count = 0;
  for (size_t i = 0; i < matches.size(); ++i) {
    const Sim3Match& m = matches[i];
    if (reprojects(K1, S12 * m.point2, m.pixel1, m.sigma1_px, chi2_threshold) &&
        reprojects(K2, S21 * m.point1, m.pixel2, m.sigma2_px, chi2_threshold)) {
      inliers[i] = 1;
      ++count;
    }
  }
  return count;
}

Sim3Result fail(Sim3Result r, std::string reason) {
  r.success = false;
  r.reason = std::move(reason);
  return r;
}

}  // namespace

std::optional<Sim3d> alignUmeyama(std::span<const Eigen::Vector3d> points1,
                                  std::span<const Eigen::Vector3d> points2, bool fix_scale) {
  if (points1.size() != points2.size()) {
    throw std::invalid_argument(
        fmt::format("alignUmeyama: {} points vs {} points", points1.size(), points2.size()));
  }
  const auto n = static_cast<Eigen::Index>(points1.size());
  Eigen::Matrix3Xd p1(3, n), p2(3, n);
  for (Eigen::Index i = 0; i < n; ++i) {
    p1.col(i) = points1[i];
    p2.col(i) = points2[i];
  }
  return fitSimilarity(p1, p2, fix_scale);
}

Sim3Result solveSim3Ransac(std::span<const Sim3Match> matches, const Eigen::Matrix3d& K1,
                           const Eigen::Matrix3d& K2, const Sim3SolverOptions& options) {
  validate(matches, K1, K2, options);
  Sim3Result result;
  result.inliers.assign(matches.size(), 0);
  const int n = static_cast<int>(matches.size());
  if (n < std::max(3, options.min_inliers)) {
    return fail(std::move(result),
                fmt::format("{} matches, need at least {}", n, std::max(3, options.min_inliers)));
  }

  const SampleSets sets = drawSampleSets(n, 3, options.max_iterations, options.seed);
  int needed_iterations = options.max_iterations;
  std::vector<char> inliers;
  int best_count = 0;
  Sim3d best;
  int it = 0;
  for (; it < needed_iterations; ++it) {
    const int* idx = sets.set(it);
    Eigen::Matrix3d p1, p2;
    for (int k = 0; k < 3; ++k) {
      p1.col(k) = matches[idx[k]].point1;
      p2.col(k) = matches[idx[k]].point2;
    }
    const auto S12 = fitSimilarity(p1, p2, options.fix_scale);
    if (!S12) continue;
    const int count = markInliers(*S12, matches, K1, K2, options.chi2_threshold, inliers);
    if (count > best_count) {
      best_count = count;
      best = *S12;
      result.inliers = inliers;
      // Standard adaptive stopping: enough iterations to draw one all-inlier triple.
      const double w = static_cast<double>(count) / n;
      const double p_fail = 1.0 - w * w * w;
      if (p_fail <= 0.0) {
        needed_iterations = it + 1;
      } else if (p_fail < 1.0) {
        const double k = std::log(1.0 - options.confidence) / std::log(p_fail);
        needed_iterations = std::min(options.max_iterations, static_cast<int>(std::ceil(k)));
      }
    }
  }
  result.iterations = it;
  if (best_count < 3) return fail(std::move(result), "no non-degenerate triple found a model");

  // Least-squares re-fit on all inliers, kept while it does not lose inliers.
  for (int round = 0; round < 2; ++round) {
    std::vector<Eigen::Vector3d> p1, p2;
    for (int i = 0; i < n; ++i) {
      if (!result.inliers[i]) continue;
      p1.push_back(matches[i].point1);
      p2.push_back(matches[i].point2);
    }
    const auto refit = alignUmeyama(p1, p2, options.fix_scale);
    if (!refit) break;
    const int count = markInliers(*refit, matches, K1, K2, options.chi2_threshold, inliers);
    if (count < best_count) break;
    best = *refit;
    best_count = count;
    result.inliers = inliers;
  }

  result.cam1_from_cam2 = best;
  result.num_inliers = best_count;
  if (best_count < options.min_inliers) {
    return fail(std::move(result),
                fmt::format("{} inliers, need at least {}", best_count, options.min_inliers));
  }
  result.success = true;
  return result;
}

}  // namespace edgeslam
