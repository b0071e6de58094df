#pragma once
// The client's own cost, fitted to the CPU it has (the paper's Table I fits the keyframe rules to
// the link; this fits the per-frame work to the device). With frames at the camera's pace, a client
// whose frames take longer than the camera's period skips frames and falls behind; this steps the
// ORB extraction down a ladder (fewer features, then fewer pyramid levels) until a frame fits, and
// back up once there is room again:
//  - decisions are taken once per window of processed frames, on the window's median frame time
//    (one slow frame, a keyframe or a preemption, moves nothing);
//  - down one step when the median exceeds `over_budget` of the period, or when the camera skipped
//    frames for at least `skipped_share` of the window (reading the camera shares the CPU too);
//  - up one step only after `up_windows` windows in a row below `under_budget` of the period with
//    no frame skipped: the step above costs more, and a ladder that climbs as readily as it falls
//    would flap.
// Not thread-safe: the frame loop owns it.
#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace edgeslam {

// One rung of the ladder: the share of the configured features kept, and the most pyramid levels
// (0: as configured).
struct ComputeStep {
  double feature_fraction = 1.0;
  int max_levels = 0;

  bool operator==(const ComputeStep&) const = default;
  // Features and levels this step leaves of a configured extractor (at least 1 level).
  int features(int configured) const;
  int levels(int configured) const;
};

inline constexpr std::size_t kComputeSteps = 4;

// Step 0 is the configuration as given. Features go first (describing, matching and tracking them
// scales with their number), then the pyramid's coarsest levels (small images, but each one a FAST
// pass and a share of the features to distribute). The last step keeps 60 % of the
// features: RGB-D initialisation wants 500 of a 640x480 frame's 1000, and a monocular map's
// triangulation thins out below that.
const std::array<ComputeStep, kComputeSteps>& computeSteps();

struct ComputeBudgetOptions {
  double period_ms = 1000.0 / 30.0;  // the camera's frame period
  std::size_t window = 15;           // processed frames per decision
  double over_budget = 0.8;          // of the period: step down above it
  double under_budget = 0.45;        // of the period: room to step up below it
  double skipped_share = 0.2;        // skipped frames per processed frame in a window: step down
  int up_windows = 4;
  // Throws std::invalid_argument for a period that is not positive and finite, an empty window, or
  // budgets out of order (0 < under < over).
  void validate() const;
};

class ComputeBudget {
 public:
  explicit ComputeBudget(ComputeBudgetOptions options);

  // One processed frame: the client's time on it (ms, wall) and the frames the camera skipped
  // since the previous one. True when the step changed (it applies from the next frame).
  bool onFrame(double frame_ms, std::size_t skipped_before);

  std::size_t step() const { return step_; }
  const ComputeStep& current() const { return computeSteps()[step_]; }
  std::uint64_t switches() const { return switches_; }
  std::size_t deepestStep() const { return deepest_; }
  // Processed frames per step (the step each frame ran with).
  const std::array<std::uint64_t, kComputeSteps>& framesPerStep() const { return frames_; }
  const ComputeBudgetOptions& options() const { return options_; }

 private:
  bool decide();

  ComputeBudgetOptions options_;
  std::size_t step_ = 0;
  std::size_t deepest_ = 0;
  std::uint64_t switches_ = 0;
  std::array<std::uint64_t, kComputeSteps> frames_{};
  std::vector<double> window_ms_;
  std::size_t window_skipped_ = 0;
  int windows_with_room_ = 0;
};

}  // namespace edgeslam
