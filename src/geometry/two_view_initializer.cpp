#include "geometry/two_view_initializer.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <future>
#include <numbers>
#include <stdexcept>

#include "geometry/chi_square.h"
#include "geometry/essential.h"
#include "geometry/fundamental.h"
#include "geometry/homography.h"
#include "geometry/ransac_sampling.h"
#include "geometry/relative_pose_refinement.h"
#include "geometry/so3.h"
#include "geometry/triangulation.h"
#include "geometry/two_view_score.h"

namespace edgeslam {
namespace {

constexpr int kFundamentalSampleSize = 8;
constexpr double kMaxRefinementRotation = 5.0 * std::numbers::pi / 180.0;
// The baseline direction is the weakly constrained part: the linear estimate can be 10+ deg off.
constexpr double kMaxRefinementTranslationAngle = 30.0 * std::numbers::pi / 180.0;
constexpr double kCauchyScaleInSigmas = 2.0;
// Refinement may move borderline points across the reprojection gate; it must not lose more.
constexpr double kMinRefinedGoodRatio = 0.95;

double radToDeg(double rad) {
  return rad * 180.0 / std::numbers::pi;
}

double median(std::vector<double> values) {
  if (values.empty()) return 0.0;
  const auto mid = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
  std::nth_element(values.begin(), mid, values.end());
  return *mid;
}

void validate(const Eigen::Matrix3d& K, const TwoViewOptions& o) {
  auto require = [](bool ok, const std::string& what) {
    if (!ok) throw std::invalid_argument("initializeTwoView: " + what);
  };
  require(K.allFinite() && K(0, 0) > 0.0 && K(1, 1) > 0.0 && K(2, 2) == 1.0 && K(1, 0) == 0.0 &&
              K(2, 0) == 0.0 && K(2, 1) == 0.0,
          "K must be an upper-triangular calibration matrix with positive focal lengths");
  require(o.min_matches >= kFundamentalSampleSize,
          fmt::format("min_matches must be >= 8 (got {})", o.min_matches));
  require(o.ransac_iterations > 0,
          fmt::format("ransac_iterations must be positive (got {})", o.ransac_iterations));
  require(o.sigma_px > 0.0, fmt::format("sigma_px must be positive (got {})", o.sigma_px));
  require(o.homography_ratio_threshold >= 0.0 && o.homography_ratio_threshold <= 1.0,
          "homography_ratio_threshold must be in [0, 1]");
  require(o.min_triangulated >= 0, "min_triangulated must not be negative");
  require(o.max_second_best_ratio > 0.0 && o.max_second_best_ratio <= 1.0,
          "max_second_best_ratio must be in (0, 1]");
  require(o.min_good_fraction >= 0.0 && o.min_good_fraction <= 1.0,
          "min_good_fraction must be in [0, 1]");
}

// One motion hypothesis triangulated on the model's inliers.
struct Hypothesis {
  SE3d cur_from_ref;
  int good = 0;
  std::vector<Eigen::Vector3d> points;  // per match, valid where good
  std::vector<char> good_flags;
  std::vector<double> parallax_deg;  // per match, valid where good
  double median_inlier_parallax_deg = 0.0;
  double ranked_inlier_parallax_deg = 0.0;  // the parallax_rank-th largest
};

Hypothesis evaluate(const SE3d& cur_from_ref, std::span<const Eigen::Vector2d> ref_px,
                    std::span<const Eigen::Vector2d> cur_px,
                    const std::vector<Eigen::Vector2d>& ref_n,
                    const std::vector<Eigen::Vector2d>& cur_n, const std::vector<char>& inliers,
                    const Eigen::Matrix3d& K, double sigma_px, int parallax_rank) {
  const size_t n = ref_px.size();
  Hypothesis h;
  h.cur_from_ref = cur_from_ref;
  h.points.assign(n, Eigen::Vector3d::Zero());
  h.good_flags.assign(n, 0);
  h.parallax_deg.assign(n, 0.0);

  const Matrix34d P1 = SE3d().matrix3x4();
  const Matrix34d P2 = cur_from_ref.matrix3x4();
  const SE3d identity;
  const Eigen::Matrix3d R_ref_from_cur = cur_from_ref.rotationMatrix().transpose();
  const double gate = chi2::kTriangulationGate * sigma_px * sigma_px;

  std::vector<double> inlier_parallax;
  for (size_t i = 0; i < n; ++i) {
    if (!inliers[i]) continue;
    // Angle between the two viewing rays once the rotation is compensated: the parallax the point
    // would have if triangulated, available even when the baseline is degenerate.
    const Eigen::Vector3d ray_ref = ref_n[i].homogeneous().normalized();
    const Eigen::Vector3d ray_cur = (R_ref_from_cur * cur_n[i].homogeneous()).normalized();
    inlier_parallax.push_back(radToDeg(std::acos(std::clamp(ray_ref.dot(ray_cur), -1.0, 1.0))));

    const auto X = triangulateDlt(P1, ref_n[i], P2, cur_n[i]);
    if (!X) continue;
    if (!isInFrontOfBoth(identity, cur_from_ref, *X)) continue;
    if (reprojectionErrorSquared(K, identity, *X, ref_px[i]) > gate) continue;
    if (reprojectionErrorSquared(K, cur_from_ref, *X, cur_px[i]) > gate) continue;
    h.points[i] = *X;
    h.good_flags[i] = 1;
    h.parallax_deg[i] = parallaxDegrees(parallaxCosine(identity, cur_from_ref, *X));
    ++h.good;
  }
  if (!inlier_parallax.empty()) {
    const auto rank =
        std::min(inlier_parallax.size(), static_cast<size_t>(std::max(parallax_rank, 1))) - 1;
    std::vector<double> sorted = inlier_parallax;
    std::nth_element(sorted.begin(), sorted.begin() + static_cast<long>(rank), sorted.end(),
                     std::greater<>());
    h.ranked_inlier_parallax_deg = sorted[rank];
  }
  h.median_inlier_parallax_deg = median(std::move(inlier_parallax));
  return h;
}

TwoViewResult fail(TwoViewResult r, TwoViewFailure failure, std::string reason) {
  r.success = false;
  r.failure = failure;
  r.reason = std::move(reason);
  return r;
}

}  // namespace

const char* toString(TwoViewModel model) {
  switch (model) {
    case TwoViewModel::kNone:
      return "none";
    case TwoViewModel::kHomography:
      return "homography";
    case TwoViewModel::kFundamental:
      return "fundamental";
  }
  return "?";
}

const char* toString(TwoViewFailure failure) {
  switch (failure) {
    case TwoViewFailure::kNone:
      return "none";
    case TwoViewFailure::kTooFewMatches:
      return "too few matches";
    case TwoViewFailure::kNoModel:
      return "no model";
    case TwoViewFailure::kLowParallax:
      return "low parallax";
    case TwoViewFailure::kTooFewTriangulated:
      return "too few triangulated points";
    case TwoViewFailure::kAmbiguousMotion:
      return "ambiguous motion";
    case TwoViewFailure::kPoorReconstruction:
      return "poor reconstruction";
  }
  return "?";
}

namespace {

struct Inputs {
  std::span<const Eigen::Vector2d> ref_px, cur_px;
  std::vector<Eigen::Vector2d> ref_n, cur_n;
  Eigen::Matrix3d K;
};

// Reconstructs with one model: motion hypotheses, the clear-winner and parallax checks, then
// refinement of the winner and its triangulation.
TwoViewResult reconstruct(TwoViewResult result, TwoViewModel model, const HomographyEstimate& h,
                          const FundamentalEstimate& f, const Inputs& in,
                          const TwoViewOptions& options) {
  const bool use_h = model == TwoViewModel::kHomography;
  const int n = static_cast<int>(in.ref_px.size());
  result.model = model;
  result.model_inliers = use_h ? h.score.inliers : f.score.inliers;
  int num_inliers = use_h ? h.score.num_inliers : f.score.num_inliers;
  result.candidate_good.clear();

  std::vector<SE3d> motions;
  if (use_h) {
    for (const auto& m : decomposeHomography(h.H21, in.K)) motions.push_back(m.cam2_from_cam1);
  } else {
    const auto candidates = decomposeEssential(essentialFromFundamental(f.F21, in.K, in.K));
    motions.assign(candidates.begin(), candidates.end());
  }
  if (motions.empty()) {
    return fail(std::move(result), TwoViewFailure::kNoModel,
                fmt::format("the {} gave no motion hypothesis", toString(model)));
  }

  std::vector<Hypothesis> hypotheses;
  hypotheses.reserve(motions.size());
  for (const SE3d& motion : motions) {
    hypotheses.push_back(evaluate(motion, in.ref_px, in.cur_px, in.ref_n, in.cur_n,
                                  result.model_inliers, in.K, options.sigma_px,
                                  options.parallax_rank));
    result.candidate_good.push_back(hypotheses.back().good);
  }
  std::vector<int> order(hypotheses.size());
  for (size_t k = 0; k < order.size(); ++k) order[k] = static_cast<int>(k);
  std::stable_sort(order.begin(), order.end(),
                   [&](int a, int b) { return hypotheses[a].good > hypotheses[b].good; });
  Hypothesis best = hypotheses[order[0]];
  result.best_good = best.good;
  result.second_best_good = order.size() > 1 ? hypotheses[order[1]].good : 0;
  result.median_parallax_deg = best.median_inlier_parallax_deg;
  result.ranked_parallax_deg = best.ranked_inlier_parallax_deg;

  auto count_triangulated = [&](const Hypothesis& hyp) {
    int count = 0;
    for (int i = 0; i < n; ++i) {
      if (hyp.good_flags[i] && hyp.parallax_deg[i] >= options.min_point_parallax_deg) ++count;
    }
    return count;
  };

  if (result.ranked_parallax_deg < options.min_parallax_deg) {
    return fail(
        std::move(result), TwoViewFailure::kLowParallax,
        fmt::format("fewer than {} inliers with parallax >= {:.2f} deg (the {}th largest is "
                    "{:.2f} deg, median {:.2f}) ({}): pure rotation or too little translation",
                    options.parallax_rank, options.min_parallax_deg, options.parallax_rank,
                    result.ranked_parallax_deg, result.median_parallax_deg, toString(model)));
  }
  if (const int count = count_triangulated(best); count < options.min_triangulated) {
    return fail(std::move(result), TwoViewFailure::kTooFewTriangulated,
                fmt::format("{} points triangulated with enough parallax, need {} ({})", count,
                            options.min_triangulated, toString(model)));
  }
  if (result.second_best_good > options.max_second_best_ratio * result.best_good) {
    return fail(std::move(result), TwoViewFailure::kAmbiguousMotion,
                fmt::format("two {} motion hypotheses fit: {} vs {} good points (ratio > {:.2f})",
                            toString(model), result.best_good, result.second_best_good,
                            options.max_second_best_ratio));
  }

  if (options.refine) {
    // Graduated re-selection: refine on the matches within a wide epipolar gate of the current
    // estimate, then narrow the gate. Selecting with the final gate straight away would keep only
    // the points that agree with the linear estimate and bias the refinement towards it.
    const double focal = 0.5 * (in.K(0, 0) + in.K(1, 1));
    const double gate = chi2::k1Dof95 * options.sigma_px * options.sigma_px / (focal * focal);
    SE3d refined = best.cur_from_ref;
    for (const double widen : {16.0, 4.0, 1.0}) {
      const Eigen::Matrix3d E = skew(refined.translation()) * refined.rotationMatrix();
      std::vector<Eigen::Vector2d> x1, x2;
      for (int i = 0; i < n; ++i) {
        const double d = sampsonDistance(E, in.ref_n[i], in.cur_n[i]);
        if (d * d >= widen * gate) continue;
        x1.push_back(in.ref_n[i]);
        x2.push_back(in.cur_n[i]);
      }
      refined =
          refineRelativePose(refined, x1, x2, kCauchyScaleInSigmas * options.sigma_px / focal);
    }
    // The refinement polishes a clear winner; a large jump means it slid elsewhere (e.g. along a
    // near-degenerate direction), in which case the linear estimate is kept.
    const bool stayed_close =
        rotationDistance(refined, best.cur_from_ref) < kMaxRefinementRotation &&
        std::acos(std::clamp(refined.translation().dot(best.cur_from_ref.translation()), -1.0,
                             1.0)) < kMaxRefinementTranslationAngle;
    // Matches the refined epipolar geometry accepts, which includes some the linear model missed.
    std::vector<char> refined_inliers(n, 0);
    int num_refined_inliers = 0;
    const Eigen::Matrix3d E = skew(refined.translation()) * refined.rotationMatrix();
    for (int i = 0; i < n; ++i) {
      const double d = sampsonDistance(E, in.ref_n[i], in.cur_n[i]);
      if (d * d < gate) {
        refined_inliers[i] = 1;
        ++num_refined_inliers;
      }
    }
    Hypothesis again = evaluate(refined, in.ref_px, in.cur_px, in.ref_n, in.cur_n, refined_inliers,
                                in.K, options.sigma_px, options.parallax_rank);
    if (stayed_close && again.good >= kMinRefinedGoodRatio * best.good) {
      best = std::move(again);
      result.model_inliers = std::move(refined_inliers);
      num_inliers = num_refined_inliers;
    }
    result.best_good = best.good;
  }

  if (result.best_good < options.min_good_fraction * num_inliers) {
    return fail(std::move(result), TwoViewFailure::kPoorReconstruction,
                fmt::format("only {} of {} {} inliers triangulate consistently (need {:.0f} %)",
                            result.best_good, num_inliers, toString(model),
                            100.0 * options.min_good_fraction));
  }
  const int num_triangulated = count_triangulated(best);
  if (num_triangulated < options.min_triangulated) {
    return fail(std::move(result), TwoViewFailure::kTooFewTriangulated,
                fmt::format("{} points triangulated with enough parallax, need {} ({})",
                            num_triangulated, options.min_triangulated, toString(model)));
  }

  result.success = true;
  result.failure = TwoViewFailure::kNone;
  result.reason.clear();
  result.current_from_reference = best.cur_from_ref;
  for (int i = 0; i < n; ++i) {
    if (best.good_flags[i] && best.parallax_deg[i] >= options.min_point_parallax_deg) {
      result.triangulated[i] = 1;
      result.points_reference[i] = best.points[i];
    }
  }
  result.num_triangulated = num_triangulated;
  return result;
}

}  // namespace

TwoViewResult initializeTwoView(std::span<const Eigen::Vector2d> reference_px,
                                std::span<const Eigen::Vector2d> current_px,
                                const Eigen::Matrix3d& K, const TwoViewOptions& options) {
  requireMatchedPoints(reference_px, current_px, "initializeTwoView");
  validate(K, options);
  const int n = static_cast<int>(reference_px.size());

  TwoViewResult result;
  result.points_reference.assign(n, Eigen::Vector3d::Zero());
  result.triangulated.assign(n, 0);
  result.model_inliers.assign(n, 0);
  if (n < options.min_matches) {
    return fail(std::move(result), TwoViewFailure::kTooFewMatches,
                fmt::format("{} matches, need at least {}", n, options.min_matches));
  }

  const SampleSets sets =
      drawSampleSets(n, kFundamentalSampleSize, options.ransac_iterations, options.seed);
  auto find_h = [&] {
    return findHomographyRansac(reference_px, current_px, sets, options.sigma_px);
  };
  auto find_f = [&] {
    return findFundamentalRansac(reference_px, current_px, sets, options.sigma_px);
  };
  HomographyEstimate h;
  FundamentalEstimate f;
  if (options.parallel) {
    auto h_future = std::async(std::launch::async, find_h);
    f = find_f();
    h = h_future.get();
  } else {
    h = find_h();
    f = find_f();
  }

  result.score_homography = h.valid ? h.score.score : 0.0;
  result.score_fundamental = f.valid ? f.score.score : 0.0;
  result.inliers_homography = h.valid ? h.score.num_inliers : 0;
  result.inliers_fundamental = f.valid ? f.score.num_inliers : 0;
  const double total = result.score_homography + result.score_fundamental;
  if (!(total > 0.0)) {
    return fail(std::move(result), TwoViewFailure::kNoModel,
                "neither a homography nor a fundamental matrix fits the matches");
  }
  result.homography_ratio = result.score_homography / total;

  Inputs in{reference_px, current_px, {}, {}, K};
  const Eigen::Matrix3d K_inv = K.inverse();
  in.ref_n.resize(n);
  in.cur_n.resize(n);
  for (int i = 0; i < n; ++i) {
    in.ref_n[i] = (K_inv * reference_px[i].homogeneous()).hnormalized();
    in.cur_n[i] = (K_inv * current_px[i].homogeneous()).hnormalized();
  }

  const bool prefer_h = result.homography_ratio > options.homography_ratio_threshold;
  if (prefer_h) return reconstruct(std::move(result), TwoViewModel::kHomography, h, f, in, options);
  TwoViewResult from_f = reconstruct(result, TwoViewModel::kFundamental, h, f, in, options);
  // Only F -> H: on a planar scene the 8-point F is degenerate, so its hypotheses are garbage that
  // refinement can make look consistent; the homography's checks are reliable in both cases.
  const bool h_usable = h.valid && h.score.num_inliers >= options.min_triangulated;
  if (from_f.success || !options.fallback_to_homography || !h_usable) return from_f;
  TwoViewResult from_h =
      reconstruct(std::move(result), TwoViewModel::kHomography, h, f, in, options);
  if (!from_h.success) {
    from_f.reason += fmt::format("; homography fallback: {}", from_h.reason);
    return from_f;
  }
  from_h.used_fallback = true;
  return from_h;
}

double normalizeToUnitMedianDepth(TwoViewResult& result) {
  std::vector<double> depths;
  for (size_t i = 0; i < result.points_reference.size(); ++i) {
    if (result.triangulated[i] && result.points_reference[i].z() > 0.0) {
      depths.push_back(result.points_reference[i].z());
    }
  }
  if (depths.empty()) return 0.0;
  const double scale = 1.0 / median(std::move(depths));
  for (size_t i = 0; i < result.points_reference.size(); ++i) {
    if (result.triangulated[i]) result.points_reference[i] *= scale;
  }
  result.current_from_reference.setTranslation(scale * result.current_from_reference.translation());
  return scale;
}

}  // namespace edgeslam
