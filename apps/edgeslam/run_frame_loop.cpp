#include "run_frame_loop.h"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cstdlib>
#include <string>
#include <utility>

#include "io/live_camera.h"
#include "modes/adaptation_loop.h"
#include "progress_line.h"
#include "route_following.h"
#include "run_viewer.h"
#include "semantic_evaluation.h"

namespace edgeslam::cli {
namespace {

// Test hook (tests/modes/live_camera_command_test.cpp): EDGESLAM_TEST_EXTRA_LOAD_MS makes each
// paced frame read that much slower, a device too slow for its camera.
double testExtraLoadMs() {
  const char* value = std::getenv("EDGESLAM_TEST_EXTRA_LOAD_MS");
  if (value == nullptr) return 0.0;
  char* end = nullptr;
  const double ms = std::strtod(value, &end);
  return end != value && ms > 0.0 ? ms : 0.0;
}

FrameLogEntry logEntry(std::size_t index, double timestamp, const TrackResult& result,
                       double load_ms, double client_ms, double e2e_ms, const SlamSystem& slam) {
  const ClientStageTimes stages = slam.lastFrameStages();
  FrameLogEntry entry{index,
                      timestamp,
                      result.state,
                      result.new_keyframe,
                      result.relocalized,
                      result.tracked_points,
                      load_ms,
                      client_ms,
                      e2e_ms,
                      stages.features_ms,
                      stages.tracking_ms,
                      stages.keyframe_ms};
  const LinkTraffic traffic = slam.linkTraffic();
  entry.uplink_bytes = traffic.uplink_bytes;
  entry.downlink_bytes = traffic.downlink_bytes;
  if (const AdaptationLoop* adaptation = slam.adaptation()) {
    entry.adaptation_row = static_cast<int>(adaptation->row());
  }
  if (const SemanticFrame* semantic = slam.lastSemanticFrame()) {
    entry.features_culled = semantic->culled;
  }
  return entry;
}

void publishToViewer(RunCompanions& companions, const FrameLogEntry& logged, double fps,
                     std::size_t keyframes, std::size_t map_points, const DatasetFrame& frame,
                     const TrackResult& result, const SlamSystem& slam) {
  viz::RunStatus& status = companions.view_status;
  status.frame = logged.index + 1;
  status.fps = fps;
  status.state = toString(result.state);
  status.tracked_points = result.tracked_points;
  status.keyframes = keyframes;
  status.map_points = map_points;
  status.client_ms = logged.client_ms;
  status.e2e_ms = logged.e2e_ms;
  status.adaptation_row = logged.adaptation_row;
  if (companions.route) {
    status.instruction = companions.route->lastText();
    status.checkpoint = companions.route->lastCheckpoint();
  }
  status.uplink_bytes = logged.uplink_bytes;
  status.downlink_bytes = logged.downlink_bytes;
  const std::optional<SE3d> camera =
      result.T_cw ? std::optional<SE3d>(result.T_cw->inverse()) : std::nullopt;
  companions.viewer->view().publishFrame(status, camera, frame.ground_truth);
  companions.viewer->publishImage(frame.color.empty() ? frame.gray : frame.color, result,
                                  slam.lastSemanticFrame());
}

void fitExtractionToTheCpu(const ComputeBudget& budget, SlamSystem& slam, std::size_t frame) {
  const std::pair<int, int> before = slam.extractionSize();
  slam.setComputeStep(budget.current());
  const std::pair<int, int> after = slam.extractionSize();
  spdlog::info("compute budget: {} at frame {}: {} features, {} pyramid levels (were {}, {})",
               after.first < before.first ? "frames do not fit the camera's period" : "room again",
               frame, after.first, after.second, before.first, before.second);
}

}  // namespace

PlayedFrames playFrames(DatasetReader& reader, const FramePlan& plan, SlamSystem& slam,
                        RunCompanions& companions, const Stopwatch& wall) {
  PlayedFrames played;
  // Records kept for every frame, reserved whole: grown by doubling they stepped up the heap of a
  // long run (--repeat) and left the slack and the copies behind.
  played.frame_log.reserve(plan.frame_count);
  if (reader.info().has_ground_truth) played.ground_truth.reserve(plan.frame_count);
  ProgressLine progress;
  std::size_t resets_seen = 0;
  // Paced runs play the dataset as a live camera: a client that falls behind takes the newest
  // frame due and skips (never reads) the ones it was too busy for, so its latency stays bounded
  // under CPU starvation instead of growing with a queue of stale frames.
  std::optional<LiveCamera> live_camera;
  if (plan.realtime) {
    live_camera.emplace(reader, plan.frame_count,
                        LiveCameraClock{.now_ms = [&wall] { return wall.elapsedMs(); },
                                        .sleep_ms = steadyLiveCameraClock().sleep_ms},
                        LiveCameraOptions{.extra_load_ms = testExtraLoadMs()});
  }
  played.configured_extraction = slam.extractionSize();
  if (plan.compute_budget && slam.setComputeStep(computeSteps()[0])) {
    played.compute_budget.emplace(*plan.compute_budget);
  }
  std::size_t skipped_before = 0;
  PassLog* pass_log = companions.pass_log;
  RouteFollowing* route = companions.route;
  std::size_t next_unpaced = 0;
  // The last frame shown, for a page that opens after the run (headers only: no pixels copied).
  cv::Mat last_image;
  TrackResult last_result;
  for (;;) {
    std::size_t i = 0;
    DatasetFrame frame;
    double due_ms = 0.0;
    if (live_camera) {
      std::optional<LiveFrame> live = live_camera->grab();
      if (!live) break;
      i = live->index;
      due_ms = live->due_ms;
      played.load_ms.add(live->load_ms);
      skipped_before = live->skipped;
      frame = std::move(live->frame);
    } else {
      if (next_unpaced >= plan.frame_count) break;
      i = next_unpaced++;
      Stopwatch load_timer;
      frame = reader.load(i);
      played.load_ms.add(load_timer.elapsedMs());
    }
    if (pass_log) {
      pass_log->beforeFrame(i, slam, companions.edge_map_size, wall.elapsedMs() / 1000.0);
    }
    if (const auto rejection = played.frame_order.check(frame.timestamp)) {
      spdlog::warn("frame {} skipped: {} (t = {:.6f} s)", i, toString(*rejection), frame.timestamp);
      continue;
    }
    if (frame.ground_truth) played.ground_truth.push_back({frame.timestamp, *frame.ground_truth});
    const std::pair<int, int> extraction = slam.extractionSize();
    Stopwatch frame_timer;
    TrackResult result = slam.process(i, frame.timestamp, frame.gray, frame.depth, frame.color);
    const double processing_ms = frame_timer.elapsedMs();
    if (companions.semantic_eval) {
      companions.semantic_eval->addFrame(i % plan.frames_per_pass, result,
                                         slam.lastSemanticFrame());
    }
    if (pass_log) pass_log->addFrame(i, frame.timestamp, result);
    if (route) {
      route->addFrame(i, frame.timestamp,
                      result.state == TrackingState::kOk ? result.T_cw : std::nullopt);
    }
    played.client_ms.add(processing_ms);
    if (played.compute_budget && played.compute_budget->onFrame(processing_ms, skipped_before)) {
      fitExtractionToTheCpu(*played.compute_budget, slam, i);
    }
    double frame_e2e_ms = processing_ms;
    if (live_camera) frame_e2e_ms = std::max(processing_ms, wall.elapsedMs() - due_ms);
    played.e2e_ms.add(frame_e2e_ms);
    played.frame_log.push_back(logEntry(i, frame.timestamp, result, played.load_ms.samples().back(),
                                        processing_ms, frame_e2e_ms, slam));
    played.frame_log.back().features = extraction.first;
    played.frame_log.back().levels = extraction.second;
    if (result.state == TrackingState::kOk) {
      ++played.tracked;
    } else if (result.state == TrackingState::kLost) {
      ++played.lost;
    }
    if (slam.mapResets() != resets_seen) {
      // A reset withdraws every pose of the map it discards: they leave `tracked`.
      resets_seen = slam.mapResets();
      played.tracked_in_discarded_maps += played.tracked;
      played.tracked = 0;
    }
    const double fps = static_cast<double>(i + 1) / std::max(1e-9, wall.elapsedMs() / 1000.0);
    const std::size_t keyframes = slam.keyFrameCount();
    const std::size_t map_points = slam.mapPointCount();
    progress.update(
        fmt::format("frame {}/{}  {:.1f} fps  {}  tracked {}  kf {}  points {}{}", i + 1,
                    plan.frame_count, fps, toString(result.state), played.tracked, keyframes,
                    map_points, route ? "  " + route->lastText() : std::string()),
        i + 1 == plan.frame_count);
    if (companions.viewer) {
      publishToViewer(companions, played.frame_log.back(), fps, keyframes, map_points, frame,
                      result, slam);
      last_image = frame.color.empty() ? frame.gray : frame.color;
      last_result = std::move(result);  // its last use
    }
  }
  progress.finish();
  if (companions.viewer && !last_image.empty()) {
    companions.viewer->publishImage(last_image, last_result, slam.lastSemanticFrame(), true);
  }
  if (pass_log) pass_log->finish(slam, companions.edge_map_size, wall.elapsedMs() / 1000.0);
  if (live_camera) {
    played.live = true;
    played.frames_skipped_late = live_camera->skipped();
    played.frames_read = live_camera->reads();
    played.frames_read_unused = live_camera->unusedReads();
  } else {
    played.frames_read = plan.frame_count;
  }
  return played;
}

}  // namespace edgeslam::cli
