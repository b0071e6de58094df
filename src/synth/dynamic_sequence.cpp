#include "synth/dynamic_sequence.h"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <stdexcept>

#include "synth/tum_sequence_writer.h"

namespace edgeslam {
namespace {

namespace fs = std::filesystem;

constexpr std::size_t kTuningSamples = 300;
constexpr double kMaxCoverage = 0.4;
constexpr int kTuningRounds = 6;

const char* const kGeneratedEntries[] = {"rgb",         "depth",     "masks",
                                         "rgb.txt",     "depth.txt", "groundtruth.txt",
                                         "camera.yaml", "masks.txt", "synth.json"};

void prepareOutput(const fs::path& out, const fs::path& dataset, bool overwrite) {
  if (out.empty()) throw std::invalid_argument("no output folder given");
  if (fs::exists(out)) {
    if (!fs::is_directory(out)) {
      throw std::runtime_error(fmt::format("output {} exists and is not a folder", out.string()));
    }
    if (fs::exists(dataset) && fs::equivalent(out, dataset)) {
      throw std::invalid_argument(
          fmt::format("output folder {} is the source dataset itself", out.string()));
    }
    if (!fs::is_empty(out)) {
      if (!overwrite) {
        throw std::runtime_error(fmt::format(
            "output folder {} is not empty (pass --overwrite to replace a generated sequence)",
            out.string()));
      }
      for (const char* entry : kGeneratedEntries) fs::remove_all(out / entry);
    }
  }
  fs::create_directories(out);
}

double percentile(std::vector<double> sorted, double share) {
  std::sort(sorted.begin(), sorted.end());
  const double position = share * static_cast<double>(sorted.size() - 1);
  const auto below = static_cast<std::size_t>(std::floor(position));
  const auto above = std::min(below + 1, sorted.size() - 1);
  const double t = position - static_cast<double>(below);
  return (1.0 - t) * sorted[below] + t * sorted[above];
}

MotionSettings motionSettings(const DynamicSequenceOptions& options, const PinholeCamera& camera,
                              double duration_s, const std::vector<PersonSprite>& sprites) {
  MotionSettings settings;
  settings.seed = options.seed;
  settings.duration_s = duration_s;
  settings.people_count = options.people_count;
  settings.image = cv::Size(camera.width(), camera.height());
  settings.fx = camera.fx();
  settings.fy = camera.fy();
  settings.cx = camera.cx();
  settings.cy = camera.cy();
  for (const PersonSprite& sprite : sprites) {
    settings.sprite_aspects.push_back(static_cast<double>(sprite.silhouette.cols) /
                                      sprite.silhouette.rows);
  }
  return settings;
}

// Chooses the base body height so that the median coverage over frames with people is close to
// the target and no frame is much above kMaxCoverage.
MotionPlan tunePlan(MotionSettings settings, const std::vector<double>& times,
                    const std::vector<PersonSprite>& sprites, double target,
                    const CompositeOptions& composite) {
  const double image_height = settings.image.height;
  settings.base_height_px = 0.9 * image_height;
  const std::size_t stride = std::max<std::size_t>(1, times.size() / kTuningSamples);
  MotionPlan plan;
  for (int round = 0; round < kTuningRounds; ++round) {
    plan = planPeopleMotion(settings);
    std::vector<double> coverage;
    for (std::size_t i = 0; i < times.size(); i += stride) {
      coverage.push_back(compositePeople(cv::Mat(), cv::Mat(), settings.image,
                                         plan.placementsAt(times[i]), sprites, composite)
                             .coverage);
    }
    const CoverageStats stats = coverageStats(coverage);
    if (stats.frames_with_people == 0 || stats.median <= 0.0) break;
    // Coverage grows with the square of the size: aim the median at the target, but keep the
    // fullest frames below kMaxCoverage.
    const double gain =
        std::min(std::sqrt(target / stats.median), std::sqrt(kMaxCoverage / stats.max));
    if (std::abs(gain - 1.0) < 0.02 || round + 1 == kTuningRounds) break;
    settings.base_height_px = std::clamp(settings.base_height_px * std::clamp(gain, 0.6, 1.6),
                                         0.3 * image_height, 2.5 * image_height);
  }
  return plan;
}

nlohmann::json describePlan(const MotionPlan& plan, const std::vector<PersonSprite>& sprites,
                            double fps) {
  nlohmann::json people = nlohmann::json::array();
  for (const PersonTrack& track : plan.people) {
    nlohmann::json walks = nlohmann::json::array();
    for (const Walk& walk : track.walks) {
      walks.push_back({{"kind", toString(walk.kind)},
                       {"start_s", walk.start_s},
                       {"duration_s", walk.duration_s},
                       {"start_frame", std::lround(walk.start_s * fps)},
                       {"end_frame", std::lround((walk.start_s + walk.duration_s) * fps)},
                       {"from_m", {walk.from.x_m, walk.from.z_m}},
                       {"to_m", {walk.to.x_m, walk.to.z_m}}});
    }
    const PersonSprite& sprite = sprites[track.sprite];
    people.push_back({{"sprite", track.sprite},
                      {"photo", sprite.photo},
                      {"mirrored", track.mirrored},
                      {"walks", walks}});
  }
  return people;
}

}  // namespace

CoverageStats coverageStats(const std::vector<double>& per_frame) {
  std::vector<double> shown;
  for (double c : per_frame) {
    if (c > 0.0) shown.push_back(c);
  }
  CoverageStats stats;
  stats.frames_with_people = shown.size();
  if (shown.empty()) return stats;
  stats.median = percentile(shown, 0.5);
  stats.p10 = percentile(shown, 0.1);
  stats.p90 = percentile(shown, 0.9);
  stats.min = *std::min_element(shown.begin(), shown.end());
  stats.max = *std::max_element(shown.begin(), shown.end());
  double sum = 0.0;
  for (double c : shown) sum += c;
  stats.mean = sum / static_cast<double>(shown.size());
  return stats;
}

DynamicSequenceSummary generateDynamicSequence(const DynamicSequenceOptions& options,
                                               const std::vector<PersonSprite>& sprites) {
  const auto started = std::chrono::steady_clock::now();
  if (sprites.empty()) throw std::invalid_argument("no people sprites to paste");
  if (!(options.target_coverage > 0.0 && options.target_coverage < 1.0)) {
    throw std::invalid_argument(
        fmt::format("target coverage {} must lie in (0, 1)", options.target_coverage));
  }
  DatasetOptions dataset_options;
  dataset_options.format = options.format;
  const auto reader = openDataset(options.dataset, dataset_options);
  const DatasetInfo& info = reader->info();
  const FrameRange range = options.frames.value_or(FrameRange{0, info.frame_count - 1});
  checkFrameRange(range, info.frame_count);
  prepareOutput(options.out, options.dataset, options.overwrite);

  const PinholeCamera& camera = reader->camera();
  const std::vector<double>& source_times = reader->timestamps();
  std::vector<double> times;  // seconds since the first output frame
  for (std::size_t i = range.first; i <= range.last; ++i) {
    times.push_back(source_times[i] - source_times[range.first]);
  }
  const MotionSettings settings = motionSettings(options, camera, times.back(), sprites);
  const MotionPlan plan =
      tunePlan(settings, times, sprites, options.target_coverage, options.composite);

  const double depth_factor = info.has_depth ? camera.intrinsics().depth_factor : 0.0;
  TumSequenceWriter writer(
      options.out,
      fmt::format("edgeslam synth-dynamic: {} frames {}-{}, seed {}", options.dataset.string(),
                  range.first, range.last, options.seed),
      depth_factor);
  DynamicSequenceSummary summary;
  summary.out = options.out;
  summary.has_depth = info.has_depth;
  summary.people = plan.people.size();
  for (std::size_t i = range.first; i <= range.last; ++i) {
    const DatasetFrame frame = reader->load(i);
    const cv::Mat& source = frame.color.empty() ? frame.gray : frame.color;
    const CompositeFrame composite =
        compositePeople(source, frame.depth, source.size(),
                        plan.placementsAt(times[i - range.first]), sprites, options.composite);
    writer.addFrame(frame.timestamp, composite.image, composite.depth_m, composite.mask,
                    frame.ground_truth);
    summary.coverage_per_frame.push_back(composite.coverage);
    ++summary.frames;
    if (options.progress) options.progress(summary.frames, range.count());
  }
  writer.finish(camera.intrinsics());
  summary.coverage = coverageStats(summary.coverage_per_frame);
  summary.base_height_px = plan.base_height_px;
  summary.elapsed_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();

  const double fps = info.fps > 0.0 ? info.fps : 30.0;
  nlohmann::json sprites_json = nlohmann::json::array();
  for (const PersonSprite& sprite : sprites) {
    sprites_json.push_back(
        {{"photo", sprite.photo},
         {"box", {sprite.box.x, sprite.box.y, sprite.box.width, sprite.box.height}},
         {"score", sprite.score}});
  }
  const CoverageStats& c = summary.coverage;
  const nlohmann::json description = {
      {"generator", "edgeslam synth-dynamic"},
      {"source",
       {{"path", options.dataset.string()},
        {"format", toString(info.format)},
        {"frames", info.frame_count},
        {"has_depth", info.has_depth}}},
      {"frame_range", {range.first, range.last}},
      {"frames", summary.frames},
      {"seed", options.seed},
      {"people_dir", options.people_dir},
      {"layout",
       {{"base_height_px", plan.base_height_px},
        {"horizon_y_px", plan.layout.horizon_y},
        {"camera_height_ratio", plan.layout.camera_height_ratio},
        {"person_height_m", plan.layout.person_height_m}}},
      {"sprites", sprites_json},
      {"people", describePlan(plan, sprites, fps)},
      {"mask", "masks/NNNNNN.png listed in masks.txt: 255 where the pasted people's alpha > 0.5"},
      {"coverage",
       {{"frames_with_people", c.frames_with_people},
        {"median", c.median},
        {"mean", c.mean},
        {"min", c.min},
        {"max", c.max},
        {"p10", c.p10},
        {"p90", c.p90},
        {"target_median", options.target_coverage},
        {"per_frame", summary.coverage_per_frame}}},
      {"elapsed_s", summary.elapsed_s}};
  std::ofstream json(options.out / "synth.json");
  json << description.dump(2) << '\n';
  if (!json) {
    throw DatasetError(fmt::format("cannot write {}", (options.out / "synth.json").string()));
  }
  return summary;
}

}  // namespace edgeslam
