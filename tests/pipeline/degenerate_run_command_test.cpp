// Degenerate input that looks valid, as a user runs it: image folders made from real 7-Scenes
// frames (a camera that does not move; a real walk with a blank stretch, a duplicated frame and a
// frame from the past), through `edgeslam run`. No map may be built from the still camera, no
// pose reported for a blank frame, and metrics.json must say why.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <string>

#include "io/dataset.h"
#include "io/temp_folder.h"
#include "support/edgeslam_command.h"
#include "support/image_folder_sequence.h"
#include "support/shared_data.h"
#include "synth/degenerate_frames.h"

namespace edgeslam {
namespace {

namespace fs = std::filesystem;
constexpr const char* kKitchen = "datasets/7scenes-redkitchen-1000";

nlohmann::json run(const fs::path& dataset, const fs::path& out, const std::string& mode) {
  const auto r = test::runEdgeslam("run --dataset " + dataset.string() +
                                   " --sensor mono --vocab none --maps none --mode " + mode +
                                   " --out " + out.string());
  EXPECT_EQ(r.exit_code, 0) << r.output;
  std::ifstream in(out / "metrics.json");
  if (!in) return {};
  return nlohmann::json::parse(in);
}

TEST(DegenerateRun, StillCameraBuildsNoMapAndMetricsSayLowParallax) {
  EDGESLAM_REQUIRE_SHARED(kKitchen);
  test::TempFolder folder;
  const fs::path still = folder / "still";
  const cv::Mat frame = openDataset(test::sharedPath(kKitchen))->load(100).gray;
  std::vector<test::StampedImage> frames;
  for (std::size_t i = 0; i < 30; ++i) frames.push_back({frame, static_cast<double>(i) / 30.0});
  test::writeImageFolder(still, frames);

  const auto m = run(still, folder / "out", "edge");
  ASSERT_FALSE(m.empty());
  EXPECT_EQ(m["tracked"], 0);
  EXPECT_EQ(m["keyframes"], 0);
  const auto& init = m["initialization"];
  ASSERT_TRUE(init.is_object()) << m.dump(2);
  EXPECT_EQ(init["map_built"], false);
  EXPECT_EQ(init["at_frame"], nullptr);
  EXPECT_EQ(init["frames_without_map"], 30);
  EXPECT_EQ(init["refused"]["low_parallax"], 29) << init.dump(2);
  EXPECT_NE(init["last_refusal"].get<std::string>().find("pure rotation or too little"),
            std::string::npos);
  ASSERT_EQ(m["warnings"].size(), 1u) << m.dump(2);
  EXPECT_NE(m["warnings"][0].get<std::string>().find("no map was built"), std::string::npos);
}

TEST(DegenerateRun, BlankStretchAndDisorderedFramesAreCountedNotTracked) {
  EDGESLAM_REQUIRE_SHARED(kKitchen);
  test::TempFolder folder;
  const fs::path walk = folder / "walk";
  test::writeImageFolder(walk, test::walkWithDisorder(*openDataset(test::sharedPath(kKitchen))));

  const auto m = run(walk, folder / "out", "local");
  ASSERT_FALSE(m.empty());
  EXPECT_EQ(m["frames"], 142);
  EXPECT_EQ(m["frames_out_of_order"]["skipped"], 2);
  EXPECT_EQ(m["frames_out_of_order"]["duplicate_timestamp"], 1);
  EXPECT_EQ(m["frames_out_of_order"]["timestamp_backwards"], 1);
  EXPECT_EQ(m["initialization"]["map_built"], true);
  EXPECT_EQ(m["lost_frames"]["too_few_features"], 10) << m.dump(2);
  EXPECT_EQ(m["lost"], m["lost_frames"]["too_few_features"].get<int>() +
                           m["lost_frames"]["tracking_failed"].get<int>());
  // Tracking resumed after the white stretch: all but the 10 white frames and the frames before
  // the map are tracked.
  const int before_map = m["initialization"]["frames_without_map"].get<int>();
  EXPECT_GE(m["tracked"].get<int>(), 140 - 10 - before_map - 5) << m.dump(2);
}

}  // namespace
}  // namespace edgeslam
