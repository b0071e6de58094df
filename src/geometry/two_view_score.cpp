#include "geometry/two_view_score.h"

#include <fmt/format.h>

#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <stdexcept>

namespace edgeslam {
namespace {

constexpr double kRankTolerance = 1e-9;

}  // namespace

void requireMatchedPoints(std::span<const Eigen::Vector2d> points1,
                          std::span<const Eigen::Vector2d> points2, const char* who) {
  if (points1.size() != points2.size()) {
    throw std::invalid_argument(fmt::format("{}: point sets differ in size ({} vs {})", who,
                                            points1.size(), points2.size()));
  }
  for (size_t i = 0; i < points1.size(); ++i) {
    if (!points1[i].allFinite() || !points2[i].allFinite()) {
      throw std::invalid_argument(fmt::format("{}: match {} has a non-finite coordinate", who, i));
    }
  }
}

std::optional<Eigen::Matrix<double, 9, 1>> nullVector9(
    const Eigen::Matrix<double, Eigen::Dynamic, 9>& A) {
  using Vector9d = Eigen::Matrix<double, 9, 1>;
  if (A.rows() < 8) return std::nullopt;
  if (A.rows() == 8) {
    // Minimal case (the RANSAC hot path): the exact kernel, an order of magnitude faster than an
    // SVD of the 8 x 9 system.
    Eigen::FullPivLU<Eigen::Matrix<double, 8, 9>> lu(A);
    lu.setThreshold(kRankTolerance);
    if (lu.rank() != 8) return std::nullopt;
    const Vector9d v = lu.kernel().col(0);
    return Vector9d(v.normalized());
  }
  // Least squares: smallest eigenvector of A^T A. On the normalised (Hartley) coordinates used
  // here the squared conditioning is harmless, and it avoids an SVD of a tall matrix.
  const Eigen::Matrix<double, 9, 9> normal = A.transpose() * A;
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 9, 9>> eig(normal);
  const auto& ev = eig.eigenvalues();  // ascending
  if (!(ev(1) > kRankTolerance * kRankTolerance * ev(8))) return std::nullopt;
  return Vector9d(eig.eigenvectors().col(0));
}

}  // namespace edgeslam
