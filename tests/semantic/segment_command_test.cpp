// `edgeslam segment` as a user runs it.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <string>

#include "io/temp_folder.h"
#include "support/edgeslam_command.h"
#include "support/shared_data.h"

namespace edgeslam {
namespace {

namespace fs = std::filesystem;

TEST(SegmentCommand, WritesAnOverlayAndListsThePeople) {
  EDGESLAM_REQUIRE_SHARED("datasets/people/zidane.jpg");
  EDGESLAM_REQUIRE_SHARED("models");
  const fs::path out = fs::temp_directory_path() / "edgeslam_segment_zidane.png";
  fs::remove(out);
  const auto result = test::runEdgeslam(
      "segment --image " + test::sharedPath("datasets/people/zidane.jpg").string() + " --models " +
      test::sharedPath("models").string() + " --out " + out.string() + " --classes person");
  ASSERT_EQ(result.exit_code, 0) << result.output;
  EXPECT_NE(result.output.find("2 instances"), std::string::npos) << result.output;
  EXPECT_NE(result.output.find("person"), std::string::npos);
  const cv::Mat overlay = cv::imread(out.string());
  EXPECT_EQ(overlay.size(), cv::Size(1280, 720));
  fs::remove(out);
}

TEST(SegmentCommand, ScoresTheSegmenterAgainstAGeneratedSequence) {
  EDGESLAM_REQUIRE_SHARED("datasets/7scenes-redkitchen-1000");
  EDGESLAM_REQUIRE_SHARED("datasets/people");
  EDGESLAM_REQUIRE_SHARED("models");
  const test::TempFolder folder;
  const fs::path sequence = folder.path() / "dynamic";
  auto result = test::runEdgeslam("synth-dynamic --dataset " +
                                  test::sharedPath("datasets/7scenes-redkitchen-1000").string() +
                                  " --people " + test::sharedPath("datasets/people").string() +
                                  " --out " + sequence.string() + " --frames 100-129 --seed 3");
  ASSERT_EQ(result.exit_code, 0) << result.output;
  result =
      test::runEdgeslam("segment --truth " + sequence.string() + " --every 5 --reduce 2 --models " +
                        test::sharedPath("models").string());
  ASSERT_EQ(result.exit_code, 0) << result.output;
  const auto at = result.output.find("IoU median ");
  ASSERT_NE(at, std::string::npos) << result.output;
  const double median = std::stod(result.output.substr(at + 11));
  std::printf("segmenter alone: IoU median %.3f on frames 100-129 every 5th\n", median);
  EXPECT_GT(median, 0.6) << result.output;
  // A folder without ground-truth masks is refused with a reason.
  result = test::runEdgeslam("segment --truth " +
                             test::sharedPath("datasets/7scenes-redkitchen-1000").string());
  EXPECT_NE(result.exit_code, 0);
  EXPECT_NE(result.output.find("masks.txt"), std::string::npos) << result.output;
}

TEST(SegmentCommand, BadInputGivesAClearError) {
  auto result = test::runEdgeslam("segment --image /nonexistent.jpg --models /nonexistent/models");
  EXPECT_NE(result.exit_code, 0);
  EXPECT_NE(result.output.find("/nonexistent/models/centernet_mbv3_coco_512.onnx"),
            std::string::npos)
      << result.output;
  result = test::runEdgeslam("segment --image x.jpg --classes person,unicorn");
  EXPECT_NE(result.exit_code, 0);
  EXPECT_NE(result.output.find("unicorn"), std::string::npos) << result.output;
  result = test::runEdgeslam("segment");
  EXPECT_NE(result.exit_code, 0);
  EXPECT_NE(result.output.find("--image"), std::string::npos) << result.output;
}

}  // namespace
}  // namespace edgeslam
