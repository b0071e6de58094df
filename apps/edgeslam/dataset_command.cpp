// `edgeslam dataset info`: what a dataset folder holds, as the readers see it.
#include <fmt/format.h>

#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "commands.h"
#include "io/camera_file.h"
#include "io/dataset.h"

namespace edgeslam::cli {
namespace {

struct InfoOptions {
  std::string dataset;
  std::string format = "auto";
  std::string camera;
  bool json = false;
};

struct GroundTruthSummary {
  std::size_t frames = 0;
  double path_length_m = 0.0;
};

// Path length over the frames that have ground truth, joining consecutive available poses.
GroundTruthSummary summarizeGroundTruth(const std::vector<std::optional<SE3d>>& poses) {
  GroundTruthSummary summary;
  const SE3d* previous = nullptr;
  for (const auto& pose : poses) {
    if (!pose) continue;
    ++summary.frames;
    if (previous != nullptr) {
      summary.path_length_m += (pose->translation() - previous->translation()).norm();
    }
    previous = &*pose;
  }
  return summary;
}

nlohmann::json cameraJson(const CameraIntrinsics& in) {
  return {{"width", in.width},
          {"height", in.height},
          {"fx", in.fx},
          {"fy", in.fy},
          {"cx", in.cx},
          {"cy", in.cy},
          {"k1", in.distortion.k1},
          {"k2", in.distortion.k2},
          {"p1", in.distortion.p1},
          {"p2", in.distortion.p2},
          {"k3", in.distortion.k3},
          {"depth_factor", in.depth_factor},
          {"baseline_m", in.baseline_m},
          {"fps", in.fps}};
}

const char* yesNo(bool value) {
  return value ? "yes" : "no";
}

void runInfo(const InfoOptions& o) {
  DatasetOptions options;
  options.format = parseDatasetFormat(o.format);
  if (!o.camera.empty()) options.camera_override = loadCameraFile(o.camera);
  const auto reader = openDataset(o.dataset, options);
  const DatasetInfo& info = reader->info();
  const auto& times = reader->timestamps();
  const double duration = times.empty() ? 0.0 : times.back() - times.front();
  const GroundTruthSummary ground_truth = summarizeGroundTruth(reader->groundTruth());

  if (o.json) {
    const nlohmann::json out = {{"path", info.path.string()},
                                {"format", toString(info.format)},
                                {"frames", info.frame_count},
                                {"duration_s", duration},
                                {"fps", info.fps},
                                {"first_timestamp_s", times.empty() ? 0.0 : times.front()},
                                {"camera", cameraJson(reader->camera().intrinsics())},
                                {"camera_description", reader->camera().describe()},
                                {"has_depth", info.has_depth},
                                {"has_stereo", info.has_stereo},
                                {"stereo_rectified", info.stereo_rectified},
                                {"has_ground_truth", info.has_ground_truth},
                                {"ground_truth_frames", ground_truth.frames},
                                {"ground_truth_path_length_m", ground_truth.path_length_m}};
    std::cout << out.dump(2) << std::endl;
    return;
  }
  fmt::print("dataset       {}\n", info.path.string());
  fmt::print("format        {}\n", toString(info.format));
  fmt::print("frames        {}\n", info.frame_count);
  fmt::print("duration      {:.3f} s\n", duration);
  fmt::print("fps           {:.3f}\n", info.fps);
  fmt::print("camera        {}{}\n", reader->camera().describe(),
             options.camera_override ? " (from --camera)" : "");
  fmt::print("depth         {}\n", yesNo(info.has_depth));
  fmt::print("stereo        {}{}\n", yesNo(info.has_stereo),
             info.has_stereo ? (info.stereo_rectified ? " (rectified)" : " (not rectified)") : "");
  if (info.has_ground_truth) {
    fmt::print("ground truth  yes, {} of {} frames, path length {:.3f} m\n", ground_truth.frames,
               info.frame_count, ground_truth.path_length_m);
  } else {
    fmt::print("ground truth  no\n");
  }
}

}  // namespace

void addDatasetCommands(CLI::App& app) {
  auto* dataset = app.add_subcommand("dataset", "Inspect datasets");
  dataset->require_subcommand(1);

  auto options = std::make_shared<InfoOptions>();
  auto* info = dataset->add_subcommand(
      "info", "Print a dataset's format, frames, duration, camera and ground truth");
  info->add_option("--dataset", options->dataset, "Dataset folder (or video file)")->required();
  info->add_option("--format", options->format, "Dataset format")
      ->check(CLI::IsMember({"auto", "tum", "kitti", "euroc", "7scenes", "images", "video"}))
      ->capture_default_str();
  info->add_option("--camera", options->camera, "Camera YAML overriding the dataset's camera");
  info->add_flag("--json", options->json, "Print exactly one JSON object");
  info->callback([options] {
    try {
      runInfo(*options);
      exitCode() = 0;
    } catch (const CLI::Error&) {
      throw;  // a usage error: main() reports it
    } catch (const std::exception& e) {
      std::cerr << "edgeslam dataset info: error: " << e.what() << std::endl;
      exitCode() = 1;
    }
  });
}

const CommandRegistration kDatasetCommandsRegistration{50, addDatasetCommands};

}  // namespace edgeslam::cli
