// `edgeslam run` as a user calls it: outputs of the DESIGN.md contract and clear errors.
#include <gtest/gtest.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "io/trajectory.h"
#include "support/edgeslam_command.h"
#include "support/shared_data.h"

namespace edgeslam {
namespace {

std::filesystem::path freshDir(const std::string& name) {
  const auto dir = std::filesystem::temp_directory_path() / ("edgeslam_run_test_" + name);
  std::filesystem::remove_all(dir);
  return dir;
}

TEST(RunCommand, WritesTheContractOutputs) {
  EDGESLAM_REQUIRE_SHARED("datasets/7scenes-redkitchen-1000");
  const auto out = freshDir("outputs");
  const auto r = test::runEdgeslam(
      "run --dataset " + test::sharedPath("datasets/7scenes-redkitchen-1000").string() +
      " --sensor rgbd --mode local --max-frames 40 --out " + out.string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("Summary"), std::string::npos);
  for (const char* file :
       {"trajectory.tum", "trajectory_final.tum", "keyframes.tum", "metrics.json", "frames.csv"}) {
    EXPECT_TRUE(std::filesystem::exists(out / file)) << file;
  }
  EXPECT_EQ(readTumTrajectory(out / "trajectory.tum").size(), 40u);
  std::ifstream in(out / "metrics.json");
  const auto metrics = nlohmann::json::parse(in);
  for (const char* key :
       {"frames", "tracked", "lost", "keyframes", "map_points", "client_ms", "e2e_ms",
        "uplink_bytes", "downlink_bytes", "bytes_per_keyframe", "slice_latency_ms",
        "segmentation_ms", "loops", "relocalizations", "mode", "sensor", "ate", "ate_final"}) {
    EXPECT_TRUE(metrics.contains(key)) << key;
  }
  EXPECT_EQ(metrics["frames"], 40);
  EXPECT_EQ(metrics["tracked"], 40);
  EXPECT_EQ(metrics["sensor"], "rgbd");
  EXPECT_LT(metrics["ate"]["rmse_m"].get<double>(), 0.05);
  for (const char* stat : {"median", "p90", "p99", "max"}) {
    EXPECT_GT(metrics["client_ms"][stat].get<double>(), 0.0) << stat;
  }
  // The client's time split by stage: extraction and tracking take time on every frame.
  for (const char* stage : {"features", "tracking", "keyframe"}) {
    ASSERT_TRUE(metrics["client_stages_ms"].contains(stage)) << stage;
  }
  EXPECT_GT(metrics["client_stages_ms"]["features"]["median"].get<double>(), 0.0);
  EXPECT_GT(metrics["client_stages_ms"]["tracking"]["median"].get<double>(), 0.0);
  EXPECT_LE(metrics["client_stages_ms"]["features"]["median"].get<double>(),
            metrics["client_ms"]["max"].get<double>());
  // One row per frame after the header, each with its state and times.
  std::ifstream frames(out / "frames.csv");
  std::string line;
  ASSERT_TRUE(std::getline(frames, line));
  EXPECT_EQ(line.rfind("frame,timestamp,state,keyframe", 0), 0u) << line;
  EXPECT_NE(line.find(",features_ms,tracking_ms,keyframe_ms"), std::string::npos) << line;
  std::size_t rows = 0, keyframes = 0;
  while (std::getline(frames, line)) {
    ++rows;
    EXPECT_NE(line.find(",ok,"), std::string::npos) << line;
    if (line.find(",ok,1,") != std::string::npos) ++keyframes;
  }
  EXPECT_EQ(rows, 40u);
  EXPECT_GE(keyframes, 1u);
}

TEST(RunCommand, MissingDatasetIsAClearError) {
  const auto r = test::runEdgeslam("run --dataset /nonexistent/edgeslam-data --out /tmp/x");
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.output.find("/nonexistent/edgeslam-data"), std::string::npos) << r.output;
}

TEST(RunCommand, RgbdWithoutDepthIsRejected) {
  EDGESLAM_REQUIRE_SHARED("datasets/kitti07-160");
  const auto r =
      test::runEdgeslam("run --dataset " + test::sharedPath("datasets/kitti07-160").string() +
                        " --sensor rgbd --max-frames 5");
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.output.find("depth"), std::string::npos) << r.output;
}

}  // namespace
}  // namespace edgeslam
