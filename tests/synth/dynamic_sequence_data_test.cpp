// Generates short dynamic sequences from the shared 7-Scenes excerpt and the shared people photos
// and reads them back as a user would.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <opencv2/imgproc.hpp>

#include "io/dataset.h"
#include "io/temp_folder.h"
#include "support/shared_data.h"
#include "synth/dynamic_sequence.h"
#include "synth/ground_truth_masks.h"

namespace edgeslam {
namespace {

namespace fs = std::filesystem;
using test::sharedPath;
using test::TempFolder;

const char* const kSevenScenes = "datasets/7scenes-redkitchen-1000";
const FrameRange kRange{100, 129};

#define REQUIRE_SYNTH_DATA()                  \
  EDGESLAM_REQUIRE_SHARED(kSevenScenes);      \
  EDGESLAM_REQUIRE_SHARED("datasets/people"); \
  EDGESLAM_REQUIRE_SHARED("models")

const std::vector<PersonSprite>& sharedSprites() {
  static const std::vector<PersonSprite> sprites = [] {
    SegmenterOptions options;
    options.model_dir = sharedPath("models");
    options.classes = {0};
    const auto segmenter = makeSegmenter(options);
    return loadPeopleSprites(sharedPath("datasets/people"), *segmenter);
  }();
  return sprites;
}

DynamicSequenceOptions sequenceOptions(const fs::path& out, std::uint64_t seed) {
  DynamicSequenceOptions options;
  options.dataset = sharedPath(kSevenScenes);
  options.out = out;
  options.seed = seed;
  options.frames = kRange;
  return options;
}

// One generated sequence shared by the tests that only read it.
struct GeneratedSequence {
  TempFolder folder;
  DynamicSequenceSummary summary;
};

const GeneratedSequence& generated() {
  static const auto sequence = [] {
    auto made = std::make_unique<GeneratedSequence>();
    made->summary =
        generateDynamicSequence(sequenceOptions(made->folder.path(), 3), sharedSprites());
    return made;
  }();
  return *sequence;
}

std::string fileBytes(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

TEST(PeopleSprites, WholePeopleWithPixelMasksFromTheSharedPhotos) {
  REQUIRE_SYNTH_DATA();
  const auto& sprites = sharedSprites();
  ASSERT_GE(sprites.size(), 3u);
  for (const PersonSprite& sprite : sprites) {
    EXPECT_GE(sprite.box.height, 150) << sprite.photo;
    EXPECT_EQ(sprite.color.size(), sprite.silhouette.size());
    EXPECT_LE(sprite.silhouette.cols, 0.6 * sprite.silhouette.rows) << sprite.photo;
    const double fill =
        cv::countNonZero(sprite.silhouette > 0.5f) / static_cast<double>(sprite.silhouette.total());
    EXPECT_GT(fill, 0.3) << sprite.photo;  // a silhouette, not a box
    EXPECT_LT(fill, 0.85) << sprite.photo;
  }
}

TEST(DynamicSequence, ReaderOpensItWithTheSourceCameraTimesAndGroundTruth) {
  REQUIRE_SYNTH_DATA();
  const auto& sequence = generated();
  EXPECT_EQ(sequence.summary.frames, kRange.count());
  EXPECT_TRUE(sequence.summary.has_depth);
  const auto source = openDataset(sharedPath(kSevenScenes));
  const auto copy = openDataset(sequence.folder.path());  // format auto
  EXPECT_EQ(copy->info().format, DatasetFormat::kTum);
  ASSERT_EQ(copy->info().frame_count, kRange.count());
  EXPECT_TRUE(copy->info().has_depth);
  EXPECT_TRUE(copy->info().has_ground_truth);
  const CameraIntrinsics& a = source->camera().intrinsics();
  const CameraIntrinsics& b = copy->camera().intrinsics();
  EXPECT_EQ(a.width, b.width);
  EXPECT_EQ(a.height, b.height);
  EXPECT_DOUBLE_EQ(a.fx, b.fx);
  EXPECT_DOUBLE_EQ(a.fy, b.fy);
  EXPECT_DOUBLE_EQ(a.cx, b.cx);
  EXPECT_DOUBLE_EQ(a.cy, b.cy);
  EXPECT_DOUBLE_EQ(a.depth_factor, b.depth_factor);
  for (std::size_t i = 0; i < kRange.count(); ++i) {
    const std::size_t s = kRange.first + i;
    EXPECT_NEAR(copy->timestamps()[i], source->timestamps()[s], 1e-6);
    ASSERT_TRUE(source->groundTruth()[s].has_value());
    ASSERT_TRUE(copy->groundTruth()[i].has_value()) << i;
    const SE3d& expected = *source->groundTruth()[s];
    const SE3d& got = *copy->groundTruth()[i];
    EXPECT_LT((expected.translation() - got.translation()).norm(), 1e-6);
    EXPECT_LT(expected.rotation().angularDistance(got.rotation()), 1e-6);
  }
}

TEST(DynamicSequence, FramesDifferFromTheSourceOnlyOnThePastedPeople) {
  REQUIRE_SYNTH_DATA();
  const auto& sequence = generated();
  const auto source = openDataset(sharedPath(kSevenScenes));
  const auto copy = openDataset(sequence.folder.path());
  const auto masks = GroundTruthMasks::open(sequence.folder.path());
  ASSERT_TRUE(masks.has_value());
  ASSERT_EQ(masks->size(), kRange.count());
  std::size_t frames_with_people = 0;
  for (std::size_t i = 0; i < kRange.count(); ++i) {
    const DatasetFrame original = source->load(kRange.first + i);
    const DatasetFrame frame = copy->load(i);
    const cv::Mat1b mask = masks->load(i);
    ASSERT_EQ(mask.size(), frame.gray.size());
    EXPECT_EQ(cv::countNonZero((mask != 0) & (mask != 255)), 0) << "mask values are 0 or 255";
    cv::Mat1b near_people;
    cv::dilate(mask, near_people, cv::Mat1b::ones(7, 7));  // the feather radius, 3 px
    cv::Mat diff;
    cv::absdiff(frame.color, original.color, diff);
    cv::Mat1b changed;
    cv::transform(diff, changed, cv::Matx13f(1, 1, 1));
    changed = changed > 0;
    EXPECT_EQ(cv::countNonZero(changed & ~near_people), 0) << "frame " << i;
    cv::Mat1b gray_changed = frame.gray != original.gray;
    EXPECT_EQ(cv::countNonZero(gray_changed & ~near_people), 0) << "frame " << i;
    const int on_people = cv::countNonZero(mask);
    if (on_people > 0) {
      ++frames_with_people;
      EXPECT_GT(cv::countNonZero(changed & mask), 0.8 * on_people) << "frame " << i;
    }
    // Depth: the source's off the people; on them in front of the real surface.
    ASSERT_EQ(frame.depth.type(), CV_32FC1);
    for (int y = 0; y < mask.rows; ++y) {
      for (int x = 0; x < mask.cols; ++x) {
        const float real = original.depth.at<float>(y, x);
        const float got = frame.depth.at<float>(y, x);
        if (!mask(y, x)) {
          ASSERT_NEAR(got, real, 1e-4) << i << ": " << x << "," << y;
        } else {
          ASSERT_GT(got, 0.0f);
          if (real > 0.0f) {
            ASSERT_LT(got, real) << i << ": " << x << "," << y;
          }
        }
      }
    }
  }
  EXPECT_GE(frames_with_people, kRange.count() / 2);
}

TEST(DynamicSequence, CoverageOfFramesWithPeopleIsTenToFortyPercent) {
  REQUIRE_SYNTH_DATA();
  const auto& sequence = generated();
  const CoverageStats& stats = sequence.summary.coverage;
  EXPECT_GE(stats.frames_with_people, kRange.count() / 2);
  EXPECT_GE(stats.median, 0.10);
  EXPECT_LE(stats.median, 0.40);
  EXPECT_LE(stats.max, 0.45);
  std::size_t in_band = 0;
  for (double c : sequence.summary.coverage_per_frame) in_band += c >= 0.10 && c <= 0.40;
  // Entering and leaving frames cover less.
  EXPECT_GE(in_band, stats.frames_with_people * 7 / 10);

  // synth.json and the mask files agree with the summary.
  std::ifstream in(sequence.folder / "synth.json");
  const nlohmann::json description = nlohmann::json::parse(in);
  EXPECT_EQ(description.at("seed").get<int>(), 3);
  EXPECT_EQ(description.at("frame_range").at(0).get<int>(), 100);
  EXPECT_EQ(description.at("frame_range").at(1).get<int>(), 129);
  EXPECT_NEAR(description.at("coverage").at("median").get<double>(), stats.median, 1e-12);
  EXPECT_GE(description.at("people").size(), 1u);
  const auto masks = GroundTruthMasks::open(sequence.folder.path());
  for (std::size_t i = 0; i < kRange.count(); ++i) {
    const cv::Mat1b mask = masks->load(i);
    EXPECT_NEAR(cv::countNonZero(mask) / static_cast<double>(mask.total()),
                sequence.summary.coverage_per_frame[i], 1e-12);
  }
}

TEST(DynamicSequence, SameSeedSameFilesOtherSeedOtherPeople) {
  REQUIRE_SYNTH_DATA();
  const auto& first = generated();
  TempFolder again, other;
  generateDynamicSequence(sequenceOptions(again.path(), 3), sharedSprites());
  for (const char* file : {"rgb/000000.png", "rgb/000017.png", "depth/000005.png",
                           "masks/000029.png", "groundtruth.txt", "masks.txt"}) {
    EXPECT_EQ(fileBytes(first.folder / file), fileBytes(again / file)) << file;
  }
  generateDynamicSequence(sequenceOptions(other.path(), 4), sharedSprites());
  int differing = 0;
  for (std::size_t i = 0; i < kRange.count(); ++i) {
    const std::string mask = fmt::format("masks/{:06d}.png", i);
    differing += fileBytes(first.folder / mask) != fileBytes(other / mask);
  }
  EXPECT_GT(differing, 20);
}

TEST(DynamicSequence, BadRangeMissingDatasetAndNonEmptyOutputAreClearErrors) {
  REQUIRE_SYNTH_DATA();
  TempFolder out;
  auto options = sequenceOptions(out / "seq", 1);
  options.frames = FrameRange{990, 1010};
  try {
    generateDynamicSequence(options, sharedSprites());
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("990-1010"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(fs::exists(out / "seq")) << "nothing is written on a bad range";

  options = sequenceOptions(out / "seq", 1);
  options.dataset = out / "no-such-dataset";
  try {
    generateDynamicSequence(options, sharedSprites());
    FAIL();
  } catch (const DatasetError& e) {
    EXPECT_NE(std::string(e.what()).find("no-such-dataset"), std::string::npos) << e.what();
  }

  test::writeText(out / "busy" / "notes.txt", "keep me");
  options = sequenceOptions(out / "busy", 1);
  options.frames = FrameRange{0, 1};
  EXPECT_THROW(generateDynamicSequence(options, sharedSprites()), std::runtime_error);
  EXPECT_TRUE(fs::exists(out / "busy" / "notes.txt"));
  options.overwrite = true;
  EXPECT_EQ(generateDynamicSequence(options, sharedSprites()).frames, 2u);
  EXPECT_TRUE(fs::exists(out / "busy" / "notes.txt")) << "only generated files are replaced";

  options = sequenceOptions(sharedPath(kSevenScenes), 1);
  options.overwrite = true;
  EXPECT_THROW(generateDynamicSequence(options, sharedSprites()), std::invalid_argument);
}

}  // namespace
}  // namespace edgeslam
