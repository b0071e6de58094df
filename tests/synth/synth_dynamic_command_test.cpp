// `edgeslam synth-dynamic` end to end: a short KITTI (grey, no depth) sequence and the errors.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "io/temp_folder.h"
#include "support/edgeslam_command.h"
#include "support/shared_data.h"

namespace edgeslam {
namespace {

using test::runEdgeslam;
using test::sharedPath;

TEST(SynthDynamicCommand, KittiExcerptBecomesAGreyTumSequenceWithMasks) {
  EDGESLAM_REQUIRE_SHARED("datasets/kitti07-160");
  EDGESLAM_REQUIRE_SHARED("datasets/people");
  EDGESLAM_REQUIRE_SHARED("models");
  test::TempFolder folder;
  const auto out = folder / "dyn";
  const auto result = runEdgeslam(
      "synth-dynamic --dataset " + sharedPath("datasets/kitti07-160").string() + " --out " +
      out.string() + " --frames 20-31 --seed 2 --num-people 2 --people " +
      sharedPath("datasets/people").string() + " --models " + sharedPath("models").string());
  ASSERT_EQ(result.exit_code, 0) << result.output;
  EXPECT_NE(result.output.find("wrote 12 frames to"), std::string::npos) << result.output;
  EXPECT_NE(result.output.find("people coverage on the"), std::string::npos) << result.output;

  const auto info = runEdgeslam("dataset info --json --dataset " + out.string());
  ASSERT_EQ(info.exit_code, 0) << info.output;
  const auto json = nlohmann::json::parse(info.output);
  EXPECT_EQ(json["format"], "tum");
  EXPECT_EQ(json["frames"], 12);
  EXPECT_EQ(json["has_depth"], false);
  EXPECT_EQ(json["ground_truth_frames"], 12);
  EXPECT_EQ(json["camera"]["width"], 1226);
  EXPECT_DOUBLE_EQ(json["camera"]["fx"].get<double>(), 707.0912);
  EXPECT_TRUE(std::filesystem::exists(out / "masks" / "000011.png"));
  EXPECT_FALSE(std::filesystem::exists(out / "depth"));
  std::ifstream in(out / "synth.json");
  const auto description = nlohmann::json::parse(in);
  EXPECT_EQ(description["people"].size(), 2u);
  EXPECT_EQ(description["source"]["format"], "kitti");
}

TEST(SynthDynamicCommand, BadFramesAndMissingDatasetFailClearly) {
  test::TempFolder folder;
  auto result = runEdgeslam("synth-dynamic --dataset /nonexistent/edgeslam-src --out " +
                            (folder / "a").string());
  EXPECT_EQ(result.exit_code, 1);
  EXPECT_NE(result.output.find("dataset not found: /nonexistent/edgeslam-src"), std::string::npos)
      << result.output;

  result = runEdgeslam("synth-dynamic --dataset /nonexistent --out " + (folder / "a").string() +
                       " --frames 5to9");
  EXPECT_EQ(result.exit_code, 1);
  EXPECT_NE(result.output.find("bad frame range '5to9'"), std::string::npos) << result.output;

  EDGESLAM_REQUIRE_SHARED("datasets/kitti07-160");
  result = runEdgeslam("synth-dynamic --dataset " + sharedPath("datasets/kitti07-160").string() +
                       " --out " + (folder / "a").string() + " --frames 100-400");
  EXPECT_EQ(result.exit_code, 1);
  EXPECT_NE(result.output.find("frame range 100-400 is outside the dataset's 160 frames"),
            std::string::npos)
      << result.output;
  EXPECT_FALSE(std::filesystem::exists(folder / "a"));
}

}  // namespace
}  // namespace edgeslam
