#include "geometry/homography.h"

#include <cmath>
#include <limits>
#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>

#include "geometry/chi_square.h"
#include "geometry/point_normalization.h"
#include "geometry/two_view_ransac.h"

namespace edgeslam {
namespace {

// Relative determinant below which a homography is treated as singular (collapses the plane).
constexpr double kMinRelativeDeterminant = 1e-9;

// DLT on already normalised points (selected by `indices`, or all when indices is empty).
std::optional<Eigen::Matrix3d> dltNormalized(std::span<const Eigen::Vector2d> n1,
                                             std::span<const Eigen::Vector2d> n2,
                                             std::span<const int> indices) {
  const size_t count = indices.empty() ? n1.size() : indices.size();
  Eigen::Matrix<double, Eigen::Dynamic, 9> A(2 * count, 9);
  for (size_t k = 0; k < count; ++k) {
    const size_t i = indices.empty() ? k : static_cast<size_t>(indices[k]);
    const double x1 = n1[i].x(), y1 = n1[i].y(), x2 = n2[i].x(), y2 = n2[i].y();
    // Rows of x2 x (H x1) = 0.
    A.row(2 * k) << 0.0, 0.0, 0.0, -x1, -y1, -1.0, y2 * x1, y2 * y1, y2;
    A.row(2 * k + 1) << x1, y1, 1.0, 0.0, 0.0, 0.0, -x2 * x1, -x2 * y1, -x2;
  }
  const auto h = nullVector9(A);
  if (!h) return std::nullopt;
  Eigen::Matrix3d H;
  H << (*h)(0), (*h)(1), (*h)(2), (*h)(3), (*h)(4), (*h)(5), (*h)(6), (*h)(7), (*h)(8);
  if (!(std::abs(H.determinant()) > kMinRelativeDeterminant * std::pow(H.norm(), 3))) {
    return std::nullopt;
  }
  return H;
}

Eigen::Matrix3d denormalize(const Eigen::Matrix3d& Hn, const Eigen::Matrix3d& T1,
                            const Eigen::Matrix3d& T2) {
  Eigen::Matrix3d H = T2.inverse() * Hn * T1;
  return H / H.norm();
}

// Squared transfer error of x1 mapped by H onto x2, +inf when mapped to infinity.
double transferErrorSquared(const Eigen::Matrix3d& H, const Eigen::Vector2d& x1,
                            const Eigen::Vector2d& x2) {
  const Eigen::Vector3d m = H * x1.homogeneous();
  if (std::abs(m.z()) < 1e-12) return std::numeric_limits<double>::infinity();
  return (m.hnormalized() - x2).squaredNorm();
}

}  // namespace

std::optional<Eigen::Matrix3d> estimateHomographyDlt(std::span<const Eigen::Vector2d> points1,
                                                     std::span<const Eigen::Vector2d> points2) {
  requireMatchedPoints(points1, points2, "estimateHomographyDlt");
  if (points1.size() < 4) return std::nullopt;
  const std::vector<Eigen::Vector2d> p1(points1.begin(), points1.end());
  const std::vector<Eigen::Vector2d> p2(points2.begin(), points2.end());
  NormalizedPoints n1, n2;
  try {
    n1 = normalizePoints(p1);
    n2 = normalizePoints(p2);
  } catch (const std::invalid_argument&) {
    return std::nullopt;  // all points coincide
  }
  const auto Hn = dltNormalized(n1.points, n2.points, {});
  if (!Hn) return std::nullopt;
  return denormalize(*Hn, n1.T, n2.T);
}

TwoViewScore scoreHomography(const Eigen::Matrix3d& H21, std::span<const Eigen::Vector2d> points1,
                             std::span<const Eigen::Vector2d> points2, double sigma_px) {
  const size_t n = points1.size();
  TwoViewScore out;
  out.inliers.assign(n, 0);
  const Eigen::FullPivLU<Eigen::Matrix3d> lu(H21);
  if (!lu.isInvertible()) return out;
  const Eigen::Matrix3d H12 = lu.inverse();
  const double inv_sigma2 = 1.0 / (sigma_px * sigma_px);
  for (size_t i = 0; i < n; ++i) {
    bool inlier = true;
    const double e21 = transferErrorSquared(H21, points1[i], points2[i]) * inv_sigma2;
    if (e21 < chi2::k2Dof95) {
      out.score += chi2::k2Dof95 - e21;
    } else {
      inlier = false;
    }
    const double e12 = transferErrorSquared(H12, points2[i], points1[i]) * inv_sigma2;
    if (e12 < chi2::k2Dof95) {
      out.score += chi2::k2Dof95 - e12;
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

HomographyEstimate findHomographyRansac(std::span<const Eigen::Vector2d> points1,
                                        std::span<const Eigen::Vector2d> points2,
                                        const SampleSets& sample_sets, double sigma_px) {
  requireMatchedPoints(points1, points2, "findHomographyRansac");
  HomographyEstimate best;
  if (points1.size() < 4 || sample_sets.sample_size < 4) return best;
  NormalizedPoints n1, n2;
  try {
    n1 = normalizePoints({points1.begin(), points1.end()});
    n2 = normalizePoints({points2.begin(), points2.end()});
  } catch (const std::invalid_argument&) {
    return best;
  }
  const TwoViewModelEstimate found = ransacWithRefit(
      points1.size(), sample_sets, 4,
      [&](std::span<const int> indices) -> std::optional<Eigen::Matrix3d> {
        const auto normalized = dltNormalized(n1.points, n2.points, indices);
        if (!normalized) return std::nullopt;
        return denormalize(*normalized, n1.T, n2.T);
      },
      [&](const Eigen::Matrix3d& model) {
        return scoreHomography(model, points1, points2, sigma_px);
      });
  best.valid = found.valid;
  if (found.valid) best.H21 = found.model;
  best.score = found.score;
  return best;
}

std::vector<HomographyMotion> decomposeHomography(const Eigen::Matrix3d& H21,
                                                  const Eigen::Matrix3d& K) {
  Eigen::Matrix3d Hn = K.inverse() * H21 * K;
  // A homography of a visible plane has positive determinant; scale so the middle singular value
  // is one, the form R + t n^T / d expects.
  if (Hn.determinant() < 0.0) Hn = -Hn;
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(Hn);
  if (!(svd.singularValues()(1) > 0.0)) return {};
  Hn /= svd.singularValues()(1);

  cv::Mat cv_h;
  cv::eigen2cv(Hn, cv_h);
  std::vector<cv::Mat> rotations, translations, normals;
  cv::decomposeHomographyMat(cv_h, cv::Mat::eye(3, 3, CV_64F), rotations, translations, normals);

  std::vector<HomographyMotion> motions;
  for (size_t k = 0; k < rotations.size(); ++k) {
    Eigen::Matrix3d R;
    Eigen::Vector3d t, n;
    cv::cv2eigen(rotations[k], R);
    cv::cv2eigen(translations[k], t);
    cv::cv2eigen(normals[k], n);
    if (!R.allFinite() || !t.allFinite()) continue;
    const double t_norm = t.norm();
    t = t_norm > 1e-12 ? Eigen::Vector3d(t / t_norm) : Eigen::Vector3d::Zero();
    motions.push_back({SE3d(R, t), n});
  }
  return motions;
}

}  // namespace edgeslam
