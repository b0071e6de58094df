// `edgeslam dataset info` end to end on the shared data.
#include <gtest/gtest.h>

#include <array>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <string>

#include "support/edgeslam_command.h"
#include "support/shared_data.h"

namespace edgeslam {
namespace {

using test::runEdgeslam;

TEST(DatasetInfoCommand, JsonOnSevenScenes) {
  EDGESLAM_REQUIRE_SHARED("datasets/7scenes-redkitchen-1000");
  const auto result = runEdgeslam("dataset info --json --dataset " +
                                  test::sharedPath("datasets/7scenes-redkitchen-1000").string());
  ASSERT_EQ(result.exit_code, 0) << result.output;
  const auto json = nlohmann::json::parse(result.output);
  EXPECT_EQ(json["format"], "7scenes");
  EXPECT_EQ(json["frames"], 1000);
  EXPECT_NEAR(json["duration_s"].get<double>(), 999.0 / 30.0, 1e-6);
  EXPECT_EQ(json["camera"]["fx"], 585.0);
  EXPECT_EQ(json["has_depth"], true);
  EXPECT_EQ(json["has_ground_truth"], true);
  // The README's "7.4 m hand-held path".
  EXPECT_NEAR(json["ground_truth_path_length_m"].get<double>(), 7.4, 0.6);
}

TEST(DatasetInfoCommand, TextOnKittiWithCameraOverride) {
  EDGESLAM_REQUIRE_SHARED("datasets/kitti07-160");
  const auto result = runEdgeslam("dataset info --format kitti --dataset " +
                                  test::sharedPath("datasets/kitti07-160").string() +
                                  " --camera " EDGESLAM_SOURCE_DIR "/config/cameras/kitti07.yaml");
  ASSERT_EQ(result.exit_code, 0) << result.output;
  EXPECT_NE(result.output.find("frames        160"), std::string::npos) << result.output;
  EXPECT_NE(result.output.find("1226x370 fx=707.091"), std::string::npos) << result.output;
  EXPECT_NE(result.output.find("(from --camera)"), std::string::npos) << result.output;
  EXPECT_NE(result.output.find("ground truth  yes, 160 of 160 frames"), std::string::npos)
      << result.output;
}

TEST(DatasetInfoCommand, BadPathFailsWithAClearMessage) {
  const auto result = runEdgeslam("dataset info --dataset /nonexistent/edgeslam-dataset");
  EXPECT_EQ(result.exit_code, 1);
  EXPECT_NE(result.output.find("dataset not found: /nonexistent/edgeslam-dataset"),
            std::string::npos)
      << result.output;
}

}  // namespace
}  // namespace edgeslam
