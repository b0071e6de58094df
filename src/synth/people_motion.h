#pragma once
// Where pasted people are in each frame. People walk on a ground plane in front of the camera
// (X lateral, Z depth, metres, camera frame) and are projected with the real camera, so their
// image height, foot line, speed in pixels and depth all agree: walking across the image,
// towards the camera (growing ~0.65x -> 1.5x) or away from it, entering and leaving through
// the image borders. Positions are relative to the camera, not anchored in the world.
#include <cstddef>
#include <cstdint>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

namespace edgeslam {

enum class WalkKind { kCross, kApproach, kRecede };
std::string toString(WalkKind kind);

struct GroundPoint {
  double x_m = 0.0;  // lateral, right positive
  double z_m = 0.0;  // depth
};

struct Walk {
  WalkKind kind = WalkKind::kCross;
  double start_s = 0.0;  // seconds after the first output frame (may be negative)
  double duration_s = 0.0;
  GroundPoint from, to;
  double step_hz = 1.8;  // walking bob frequency
};

struct PersonTrack {
  std::size_t sprite = 0;
  bool mirrored = false;
  double aspect = 0.4;  // sprite width / height
  std::vector<Walk> walks;
};

// How a person standing at (X, Z) projects into the image.
struct SceneLayout {
  cv::Size image;
  double fx = 0.0, fy = 0.0, cx = 0.0;
  double horizon_y = 0.0;            // image row of the (level) horizon
  double camera_height_ratio = 0.9;  // camera height above the ground / person height
  double person_height_m = 1.7;
};

struct PersonPlacement {
  std::size_t person = 0;
  std::size_t sprite = 0;
  bool mirrored = false;
  double center_x = 0.0;   // pixel column of the person's centre line
  double foot_y = 0.0;     // pixel row of the soles (may lie below the image)
  double height_px = 0.0;  // full body height in pixels
  double depth_m = 0.0;    // nominal distance from the camera
};

struct MotionSettings {
  std::uint64_t seed = 1;
  double duration_s = 10.0;  // time span of the output sequence
  int people_count = 0;      // 0: 1-3, drawn from the seed
  cv::Size image;
  double fx = 0.0, fy = 0.0, cx = 0.0, cy = 0.0;
  double base_height_px = 0.0;         // body height of a person walking across (before variations)
  std::vector<double> sprite_aspects;  // width / height of every available sprite
};

struct MotionPlan {
  SceneLayout layout;
  std::vector<PersonTrack> people;
  double base_height_px = 0.0;  // from the settings
  // The people visible (at least partly inside the image) at `time_s`, farthest first.
  std::vector<PersonPlacement> placementsAt(double time_s) const;
};

// Deterministic for equal settings. Throws std::invalid_argument on settings that make no sense.
MotionPlan planPeopleMotion(const MotionSettings& settings);

}  // namespace edgeslam
