#include "synth/people_motion.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <stdexcept>

#include "synth/deterministic_random.h"

namespace edgeslam {
namespace {

constexpr double kPersonHeightM = 1.7;
constexpr double kOffscreenMarginM = 0.05;
constexpr double kBobAmplitude = 0.012;  // of the body height

struct Planner {
  const MotionSettings& settings;
  const SceneLayout& layout;
  DeterministicRandom& random;

  double halfWidthM(double aspect) const {
    return 0.5 * kPersonHeightM * aspect * settings.fy / settings.fx;
  }
  // Lateral position at depth z where the person is just outside the left (-1) or right (+1)
  // border.
  double offscreenX(int side, double z, double aspect) const {
    const double border_px = side < 0 ? settings.cx : settings.image.width - settings.cx;
    return side * (border_px * z / settings.fx + halfWidthM(aspect) + kOffscreenMarginM);
  }

  Walk makeWalk(WalkKind kind, double base_depth, double aspect) {
    Walk walk;
    walk.kind = kind;
    const int side = random.chance(0.5) ? -1 : 1;
    double z_from = 0.0, z_to = 0.0;
    switch (kind) {
      case WalkKind::kCross:
        z_from = base_depth * random.uniform(0.85, 1.2);
        z_to = z_from * random.uniform(0.85, 1.15);
        break;
      case WalkKind::kApproach:
        z_from = base_depth / random.uniform(0.6, 0.7);
        z_to = base_depth / random.uniform(1.4, 1.6);
        break;
      case WalkKind::kRecede:
        z_from = base_depth / random.uniform(1.4, 1.6);
        z_to = base_depth / random.uniform(0.6, 0.7);
        break;
    }
    walk.from = {offscreenX(side, z_from, aspect), z_from};
    walk.to = {offscreenX(-side, z_to, aspect), z_to};
    const double speed = random.uniform(1.0, 1.5);
    walk.duration_s = std::hypot(walk.to.x_m - walk.from.x_m, walk.to.z_m - walk.from.z_m) / speed;
    walk.step_hz = 1.4 * speed;
    return walk;
  }

  WalkKind randomKind() {
    const double u = random.unit();
    return u < 0.4 ? WalkKind::kCross : (u < 0.7 ? WalkKind::kApproach : WalkKind::kRecede);
  }
};

}  // namespace

std::string toString(WalkKind kind) {
  switch (kind) {
    case WalkKind::kCross:
      return "cross";
    case WalkKind::kApproach:
      return "approach";
    case WalkKind::kRecede:
      return "recede";
  }
  return "unknown";
}

MotionPlan planPeopleMotion(const MotionSettings& settings) {
  if (settings.image.width <= 0 || settings.image.height <= 0 || settings.fx <= 0.0 ||
      settings.fy <= 0.0) {
    throw std::invalid_argument("planPeopleMotion: image size and focal lengths must be positive");
  }
  if (settings.base_height_px <= 0.0) {
    throw std::invalid_argument("planPeopleMotion: base_height_px must be positive");
  }
  if (settings.sprite_aspects.empty()) {
    throw std::invalid_argument("planPeopleMotion: no sprite to place");
  }
  if (settings.people_count < 0 || settings.people_count > 3) {
    throw std::invalid_argument("planPeopleMotion: people_count must be 0 (auto) or 1-3");
  }
  if (!(settings.duration_s >= 0.0)) {
    throw std::invalid_argument("planPeopleMotion: negative duration");
  }
  DeterministicRandom random(settings.seed);
  MotionPlan plan;
  SceneLayout& layout = plan.layout;
  layout.image = settings.image;
  layout.fx = settings.fx;
  layout.fy = settings.fy;
  layout.cx = settings.cx;
  layout.person_height_m = kPersonHeightM;
  plan.base_height_px = settings.base_height_px;
  layout.horizon_y = settings.cy - random.uniform(0.0, 0.12) * settings.image.height;
  layout.camera_height_ratio = random.uniform(0.8, 0.95);

  const std::size_t count = settings.people_count > 0
                                ? static_cast<std::size_t>(settings.people_count)
                                : 1 + random.index(3);
  std::array<WalkKind, 3> first_kinds{WalkKind::kCross, WalkKind::kApproach, WalkKind::kRecede};
  std::swap(first_kinds[0], first_kinds[random.index(3)]);
  std::swap(first_kinds[1], first_kinds[1 + random.index(2)]);
  const std::size_t sprite_offset = random.index(settings.sprite_aspects.size());
  const double base_depth = settings.fy * kPersonHeightM / settings.base_height_px;

  Planner planner{settings, layout, random};
  for (std::size_t k = 0; k < count; ++k) {
    PersonTrack track;
    track.sprite = (sprite_offset + k) % settings.sprite_aspects.size();
    track.aspect = settings.sprite_aspects[track.sprite];
    track.mirrored = random.chance(0.5);
    double time = 0.0;
    for (bool first = true; first || time < settings.duration_s; first = false) {
      const WalkKind kind = first ? first_kinds[k % first_kinds.size()] : planner.randomKind();
      Walk walk = planner.makeWalk(kind, base_depth, track.aspect);
      if (first) {
        // The first person is already on stage at the first frame; the others come in later.
        time = k == 0 ? -random.uniform(0.25, 0.45) * walk.duration_s
                      : random.uniform(-0.6 * walk.duration_s, 0.4 * settings.duration_s);
      }
      walk.start_s = time;
      track.walks.push_back(walk);
      time += walk.duration_s + random.uniform(0.3, 1.5);
    }
    plan.people.push_back(std::move(track));
  }
  return plan;
}

std::vector<PersonPlacement> MotionPlan::placementsAt(double time_s) const {
  std::vector<PersonPlacement> visible;
  const cv::Rect2d image_rect(0, 0, layout.image.width, layout.image.height);
  for (std::size_t p = 0; p < people.size(); ++p) {
    const PersonTrack& track = people[p];
    for (const Walk& walk : track.walks) {
      const double elapsed = time_s - walk.start_s;
      if (elapsed < 0.0 || elapsed > walk.duration_s) continue;
      const double s = walk.duration_s > 0.0 ? elapsed / walk.duration_s : 0.0;
      const double x = walk.from.x_m + s * (walk.to.x_m - walk.from.x_m);
      const double z = walk.from.z_m + s * (walk.to.z_m - walk.from.z_m);
      PersonPlacement placement;
      placement.person = p;
      placement.sprite = track.sprite;
      placement.mirrored = track.mirrored;
      placement.depth_m = z;
      placement.height_px = layout.fy * layout.person_height_m / z;
      placement.center_x = layout.cx + layout.fx * x / z;
      const double bob = kBobAmplitude * placement.height_px *
                         (0.5 - 0.5 * std::cos(2.0 * std::numbers::pi * walk.step_hz * elapsed));
      placement.foot_y = layout.horizon_y + layout.camera_height_ratio * placement.height_px - bob;
      const double width = placement.height_px * track.aspect;
      const cv::Rect2d body(placement.center_x - 0.5 * width,
                            placement.foot_y - placement.height_px, width, placement.height_px);
      if ((body & image_rect).area() > 0.0) visible.push_back(placement);
      break;
    }
  }
  std::sort(visible.begin(), visible.end(),
            [](const auto& a, const auto& b) { return a.depth_m > b.depth_m; });
  return visible;
}

}  // namespace edgeslam
