#include "geometry/camera.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <opencv2/calib3d.hpp>
#include <stdexcept>

namespace edgeslam {
namespace {

void require(bool ok, const std::string& what) {
  if (!ok) throw std::invalid_argument("camera: " + what);
}

}  // namespace

PinholeCamera::PinholeCamera(const CameraIntrinsics& in) : intrinsics_(in) {
  require(in.width > 0 && in.height > 0,
          fmt::format("width and height must be positive (got {}x{})", in.width, in.height));
  require(std::isfinite(in.fx) && in.fx > 0.0, fmt::format("fx must be positive (got {})", in.fx));
  require(std::isfinite(in.fy) && in.fy > 0.0, fmt::format("fy must be positive (got {})", in.fy));
  require(std::isfinite(in.cx) && std::isfinite(in.cy), "cx and cy must be finite");
  require(in.baseline_m >= 0.0, "baseline_m must not be negative");
  require(in.depth_factor >= 0.0, "depth_factor must not be negative");
  require(in.fps >= 0.0, "fps must not be negative");
  const Distortion& d = in.distortion;
  require(std::isfinite(d.k1) && std::isfinite(d.k2) && std::isfinite(d.p1) &&
              std::isfinite(d.p2) && std::isfinite(d.k3),
          "distortion coefficients must be finite");

  const double w = in.width, h = in.height;
  bounds_ = {0.0, w, 0.0, h};
  if (hasDistortion()) {
    const std::vector<cv::Point2f> corners = {{0.f, 0.f},
                                              {static_cast<float>(w), 0.f},
                                              {0.f, static_cast<float>(h)},
                                              {static_cast<float>(w), static_cast<float>(h)}};
    const auto u = undistort(corners);
    bounds_.min_x = std::min(u[0].x, u[2].x);
    bounds_.max_x = std::max(u[1].x, u[3].x);
    bounds_.min_y = std::min(u[0].y, u[1].y);
    bounds_.max_y = std::max(u[2].y, u[3].y);
  }
}

Eigen::Matrix3d PinholeCamera::K() const {
  Eigen::Matrix3d k;
  k << fx(), 0.0, cx(), 0.0, fy(), cy(), 0.0, 0.0, 1.0;
  return k;
}

cv::Mat PinholeCamera::cvK() const {
  return (cv::Mat_<double>(3, 3) << fx(), 0.0, cx(), 0.0, fy(), cy(), 0.0, 0.0, 1.0);
}

cv::Mat PinholeCamera::cvDistortion() const {
  const Distortion& d = intrinsics_.distortion;
  return (cv::Mat_<double>(1, 5) << d.k1, d.k2, d.p1, d.p2, d.k3);
}

std::optional<Eigen::Vector2d> PinholeCamera::project(const Eigen::Vector3d& p) const {
  if (!(p.z() > 1e-9)) return std::nullopt;
  const double inv_z = 1.0 / p.z();
  return Eigen::Vector2d(fx() * p.x() * inv_z + cx(), fy() * p.y() * inv_z + cy());
}

std::optional<Eigen::Vector2d> PinholeCamera::projectDistorted(const Eigen::Vector3d& p) const {
  const auto ideal = project(p);
  if (!ideal) return std::nullopt;
  return distort(*ideal);
}

Eigen::Vector3d PinholeCamera::unproject(const Eigen::Vector2d& px) const {
  return {(px.x() - cx()) / fx(), (px.y() - cy()) / fy(), 1.0};
}

Eigen::Vector2d PinholeCamera::distort(const Eigen::Vector2d& px) const {
  if (!hasDistortion()) return px;
  const Distortion& d = intrinsics_.distortion;
  const double x = (px.x() - cx()) / fx();
  const double y = (px.y() - cy()) / fy();
  const double r2 = x * x + y * y;
  const double radial = 1.0 + r2 * (d.k1 + r2 * (d.k2 + r2 * d.k3));
  const double xd = x * radial + 2.0 * d.p1 * x * y + d.p2 * (r2 + 2.0 * x * x);
  const double yd = y * radial + d.p1 * (r2 + 2.0 * y * y) + 2.0 * d.p2 * x * y;
  return {fx() * xd + cx(), fy() * yd + cy()};
}

Eigen::Vector2d PinholeCamera::undistort(const Eigen::Vector2d& px) const {
  if (!hasDistortion()) return px;
  const auto out = undistort(std::vector<cv::Point2f>{
      cv::Point2f(static_cast<float>(px.x()), static_cast<float>(px.y()))});
  return {out[0].x, out[0].y};
}

std::vector<cv::Point2f> PinholeCamera::undistort(const std::vector<cv::Point2f>& px) const {
  if (!hasDistortion() || px.empty()) return px;
  std::vector<cv::Point2f> out;
  // OpenCV's default of 5 fixed iterations leaves pixels of error at strong distortion; iterate
  // to convergence instead.
  cv::undistortPoints(px, out, cvK(), cvDistortion(), cv::noArray(), cvK(),
                      cv::TermCriteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 50, 1e-10));
  return out;
}

bool PinholeCamera::isInImage(const Eigen::Vector2d& px) const {
  return px.x() >= bounds_.min_x && px.x() < bounds_.max_x && px.y() >= bounds_.min_y &&
         px.y() < bounds_.max_y;
}

std::string PinholeCamera::describe() const {
  const CameraIntrinsics& in = intrinsics_;
  std::string s = fmt::format("{}x{} fx={:.3f} fy={:.3f} cx={:.3f} cy={:.3f}", in.width, in.height,
                              in.fx, in.fy, in.cx, in.cy);
  if (hasDistortion()) {
    const Distortion& d = in.distortion;
    s += fmt::format(" k1={} k2={} p1={} p2={} k3={}", d.k1, d.k2, d.p1, d.p2, d.k3);
  }
  if (in.baseline_m > 0.0) s += fmt::format(" baseline={:.4f}m", in.baseline_m);
  if (in.depth_factor > 0.0) s += fmt::format(" depth_factor={}", in.depth_factor);
  if (in.fps > 0.0) s += fmt::format(" fps={}", in.fps);
  return s;
}

}  // namespace edgeslam
