#include "geometry/pnp.h"

#include <fmt/format.h>

#include <Eigen/Eigenvalues>
#include <cmath>
#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>
#include <stdexcept>

namespace edgeslam {
namespace {

// Relative spread below which world points count as coincident / collinear.
constexpr double kDegenerateSpread = 1e-6;

void validate(std::span<const Eigen::Vector2d> pixels,
              std::span<const Eigen::Vector3d> points_world, const Eigen::Matrix3d& K,
              const PnpOptions& o) {
  auto require = [](bool ok, const std::string& what) {
    if (!ok) throw std::invalid_argument("solvePnpRansac: " + what);
  };
  require(pixels.size() == points_world.size(),
          fmt::format("{} pixels but {} world points", pixels.size(), points_world.size()));
  for (size_t i = 0; i < pixels.size(); ++i) {
    require(pixels[i].allFinite() && points_world[i].allFinite(),
            fmt::format("correspondence {} has a non-finite coordinate", i));
  }
  require(K.allFinite() && K(0, 0) > 0.0 && K(1, 1) > 0.0 && K(2, 2) == 1.0,
          "K must be a calibration matrix with positive focal lengths");
  require(o.max_iterations > 0, "max_iterations must be positive");
  require(o.reprojection_threshold_px > 0.0, "reprojection_threshold_px must be positive");
  require(o.confidence > 0.0 && o.confidence < 1.0, "confidence must be in (0, 1)");
  require(o.min_correspondences >= 4, "min_correspondences must be >= 4");
  require(o.min_inliers >= 4, "min_inliers must be >= 4");
}

// Eigenvalues (ascending) of the covariance of the points.
template <int D>
Eigen::Matrix<double, D, 1> spread(std::span<const Eigen::Matrix<double, D, 1>> points) {
  Eigen::Matrix<double, D, 1> mean = Eigen::Matrix<double, D, 1>::Zero();
  for (const auto& p : points) mean += p;
  mean /= static_cast<double>(points.size());
  Eigen::Matrix<double, D, D> cov = Eigen::Matrix<double, D, D>::Zero();
  for (const auto& p : points) cov += (p - mean) * (p - mean).transpose();
  cov /= static_cast<double>(points.size());
  return Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, D, D>>(cov).eigenvalues();
}

PnpResult fail(PnpResult r, std::string reason) {
  r.success = false;
  r.reason = std::move(reason);
  return r;
}

// Marks the inliers of a pose and returns the sum of their squared errors.
double markInliers(const SE3d& pose, std::span<const Eigen::Vector2d> pixels,
                   std::span<const Eigen::Vector3d> points_world, const Eigen::Matrix3d& K,
                   double threshold_px, std::vector<char>& inliers, int& num_inliers) {
  const double gate = threshold_px * threshold_px;
  double sum = 0.0;
  num_inliers = 0;
  inliers.assign(pixels.size(), 0);
  for (size_t i = 0; i < pixels.size(); ++i) {
    const Eigen::Vector3d pc = pose * points_world[i];
    if (!(pc.z() > 0.0)) continue;
    const double e2 = ((K * pc).hnormalized() - pixels[i]).squaredNorm();
    if (e2 < gate) {
      inliers[i] = 1;
      ++num_inliers;
      sum += e2;
    }
  }
  return sum;
}

SE3d poseFromCv(const cv::Mat& rvec, const cv::Mat& tvec) {
  cv::Mat R_cv;
  cv::Rodrigues(rvec, R_cv);
  Eigen::Matrix3d R;
  Eigen::Vector3d t;
  cv::cv2eigen(R_cv, R);
  cv::cv2eigen(tvec, t);
  return SE3d(R, t);
}

}  // namespace

PnpResult solvePnpRansac(std::span<const Eigen::Vector2d> pixels,
                         std::span<const Eigen::Vector3d> points_world, const Eigen::Matrix3d& K,
                         const PnpOptions& options) {
  validate(pixels, points_world, K, options);
  PnpResult result;
  result.inliers.assign(pixels.size(), 0);
  const int n = static_cast<int>(pixels.size());
  if (n < options.min_correspondences) {
    return fail(std::move(result), fmt::format("{} correspondences, need at least {}", n,
                                               options.min_correspondences));
  }
  const Eigen::Vector3d world_spread = spread<3>(points_world);
  if (!(world_spread(2) > 0.0)) {
    return fail(std::move(result), "degenerate input: all world points coincide");
  }
  if (!(world_spread(1) > kDegenerateSpread * world_spread(2))) {
    return fail(std::move(result), "degenerate input: world points are collinear");
  }
  if (!(spread<2>(pixels)(1) > 0.0)) {
    return fail(std::move(result), "degenerate input: all pixels coincide");
  }

  std::vector<cv::Point3d> object(n);
  std::vector<cv::Point2d> image(n);
  for (int i = 0; i < n; ++i) {
    object[i] = {points_world[i].x(), points_world[i].y(), points_world[i].z()};
    image[i] = {pixels[i].x(), pixels[i].y()};
  }
  cv::Mat K_cv;
  cv::eigen2cv(K, K_cv);
  cv::Mat rvec, tvec;
  std::vector<int> cv_inliers;
  const bool found = cv::solvePnPRansac(object, image, K_cv, cv::noArray(), rvec, tvec, false,
                                        options.max_iterations,
                                        static_cast<float>(options.reprojection_threshold_px),
                                        options.confidence, cv_inliers, cv::SOLVEPNP_AP3P);
  if (!found || rvec.empty() || tvec.empty()) {
    return fail(std::move(result), "RANSAC found no pose");
  }
  SE3d pose = poseFromCv(rvec, tvec);
  if (!pose.translation().allFinite() || !pose.rotation().coeffs().allFinite()) {
    return fail(std::move(result), "RANSAC returned a non-finite pose");
  }

  int num_inliers = 0;
  double sum_sq = markInliers(pose, pixels, points_world, K, options.reprojection_threshold_px,
                              result.inliers, num_inliers);
  // Refine on the inliers and re-select them; twice is enough for the set to settle.
  for (int round = 0; options.refine && round < 2 && num_inliers >= 4; ++round) {
    std::vector<cv::Point3d> obj_in;
    std::vector<cv::Point2d> img_in;
    for (int i = 0; i < n; ++i) {
      if (!result.inliers[i]) continue;
      obj_in.push_back(object[i]);
      img_in.push_back(image[i]);
    }
    cv::solvePnPRefineLM(obj_in, img_in, K_cv, cv::noArray(), rvec, tvec);
    const SE3d refined = poseFromCv(rvec, tvec);
    std::vector<char> inliers;
    int refined_inliers = 0;
    const double refined_sum =
        markInliers(refined, pixels, points_world, K, options.reprojection_threshold_px, inliers,
                    refined_inliers);
    if (refined_inliers < num_inliers) break;
    pose = refined;
    result.inliers = std::move(inliers);
    num_inliers = refined_inliers;
    sum_sq = refined_sum;
  }

  result.camera_from_world = pose;
  result.num_inliers = num_inliers;
  result.rmse_px = num_inliers > 0 ? std::sqrt(sum_sq / num_inliers) : 0.0;
  if (num_inliers < options.min_inliers) {
    return fail(std::move(result),
                fmt::format("{} inliers, need at least {}", num_inliers, options.min_inliers));
  }
  result.success = true;
  return result;
}

}  // namespace edgeslam
