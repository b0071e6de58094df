#include "geometry/fundamental.h"

#include <Eigen/Geometry>
#include <Eigen/SVD>
#include <cmath>
#include <limits>

#include "geometry/chi_square.h"
#include "geometry/point_normalization.h"
#include "geometry/two_view_ransac.h"

namespace edgeslam {
namespace {

std::optional<Eigen::Matrix3d> eightPointNormalized(std::span<const Eigen::Vector2d> n1,
                                                    std::span<const Eigen::Vector2d> n2,
                                                    std::span<const int> indices) {
  const size_t count = indices.empty() ? n1.size() : indices.size();
  if (count < 8) return std::nullopt;
  Eigen::Matrix<double, Eigen::Dynamic, 9> A(count, 9);
  for (size_t k = 0; k < count; ++k) {
    const size_t i = indices.empty() ? k : static_cast<size_t>(indices[k]);
    const double x1 = n1[i].x(), y1 = n1[i].y(), x2 = n2[i].x(), y2 = n2[i].y();
    A.row(k) << x2 * x1, x2 * y1, x2, y2 * x1, y2 * y1, y2, x1, y1, 1.0;
  }
  const auto f = nullVector9(A);
  if (!f) return std::nullopt;
  Eigen::Matrix3d F;
  F << (*f)(0), (*f)(1), (*f)(2), (*f)(3), (*f)(4), (*f)(5), (*f)(6), (*f)(7), (*f)(8);

  // Closest rank-2 matrix in Frobenius norm.
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(F, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Vector3d sv = svd.singularValues();
  if (!(sv(1) > 1e-12 * sv(0))) return std::nullopt;
  sv(2) = 0.0;
  return svd.matrixU() * sv.asDiagonal() * svd.matrixV().transpose();
}

Eigen::Matrix3d denormalize(const Eigen::Matrix3d& Fn, const Eigen::Matrix3d& T1,
                            const Eigen::Matrix3d& T2) {
  Eigen::Matrix3d F = T2.transpose() * Fn * T1;
  return F / F.norm();
}

// Squared distance of x to the line l = (a, b, c); +inf for a degenerate line.
double pointLineDistanceSquared(const Eigen::Vector3d& l, const Eigen::Vector2d& x) {
  const double norm2 = l.x() * l.x() + l.y() * l.y();
  if (!(norm2 > 0.0)) return std::numeric_limits<double>::infinity();
  const double num = l.x() * x.x() + l.y() * x.y() + l.z();
  return num * num / norm2;
}

}  // namespace

std::optional<Eigen::Matrix3d> estimateFundamentalEightPoint(
    std::span<const Eigen::Vector2d> points1, std::span<const Eigen::Vector2d> points2) {
  requireMatchedPoints(points1, points2, "estimateFundamentalEightPoint");
  if (points1.size() < 8) return std::nullopt;
  NormalizedPoints n1, n2;
  try {
    n1 = normalizePoints({points1.begin(), points1.end()});
    n2 = normalizePoints({points2.begin(), points2.end()});
  } catch (const std::invalid_argument&) {
    return std::nullopt;
  }
  const auto Fn = eightPointNormalized(n1.points, n2.points, {});
  if (!Fn) return std::nullopt;
  return denormalize(*Fn, n1.T, n2.T);
}

TwoViewScore scoreFundamental(const Eigen::Matrix3d& F21, std::span<const Eigen::Vector2d> points1,
                              std::span<const Eigen::Vector2d> points2, double sigma_px) {
  const size_t n = points1.size();
  TwoViewScore out;
  out.inliers.assign(n, 0);
  const double inv_sigma2 = 1.0 / (sigma_px * sigma_px);
  for (size_t i = 0; i < n; ++i) {
    bool inlier = true;
    const Eigen::Vector3d line2 = F21 * points1[i].homogeneous();
    const double e2 = pointLineDistanceSquared(line2, points2[i]) * inv_sigma2;
    if (e2 < chi2::k1Dof95) {
      out.score += chi2::k2Dof95 - e2;
    } else {
      inlier = false;
    }
    const Eigen::Vector3d line1 = F21.transpose() * points2[i].homogeneous();
    const double e1 = pointLineDistanceSquared(line1, points1[i]) * inv_sigma2;
    if (e1 < chi2::k1Dof95) {
      out.score += chi2::k2Dof95 - e1;
    } else {
      inlier = false;
    }
    if (inlier) {
      out.inliers[i] = 1;
      ++out.num_inliers;
    }
  }
  return out;
}

FundamentalEstimate findFundamentalRansac(std::span<const Eigen::Vector2d> points1,
                                          std::span<const Eigen::Vector2d> points2,
                                          const SampleSets& sample_sets, double sigma_px) {
  requireMatchedPoints(points1, points2, "findFundamentalRansac");
  FundamentalEstimate best;
  if (points1.size() < 8 || sample_sets.sample_size < 8) return best;
  NormalizedPoints n1, n2;
  try {
    n1 = normalizePoints({points1.begin(), points1.end()});
    n2 = normalizePoints({points2.begin(), points2.end()});
  } catch (const std::invalid_argument&) {
    return best;
  }
  const TwoViewModelEstimate found = ransacWithRefit(
      points1.size(), sample_sets, 8,
      [&](std::span<const int> indices) -> std::optional<Eigen::Matrix3d> {
        const auto normalized = eightPointNormalized(n1.points, n2.points, indices);
        if (!normalized) return std::nullopt;
        return denormalize(*normalized, n1.T, n2.T);
      },
      [&](const Eigen::Matrix3d& model) {
        return scoreFundamental(model, points1, points2, sigma_px);
      });
  best.valid = found.valid;
  if (found.valid) best.F21 = found.model;
  best.score = found.score;
  return best;
}

}  // namespace edgeslam
