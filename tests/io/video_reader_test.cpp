#include <gtest/gtest.h>

#include <opencv2/videoio.hpp>

#include "io/dataset.h"
#include "temp_folder.h"

namespace edgeslam {
namespace {

using test::TempFolder;

constexpr int kFrames = 6;

// Frame i is a flat grey of 30 * (i + 1): easy to recognise after lossy MJPG coding.
bool writeVideo(const std::filesystem::path& path) {
  cv::VideoWriter writer(path.string(), cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), 10.0,
                         cv::Size(64, 48), true);
  if (!writer.isOpened()) return false;
  for (int i = 0; i < kFrames; ++i) {
    writer.write(cv::Mat(48, 64, CV_8UC3, cv::Scalar::all(30.0 * (i + 1))));
  }
  return true;
}

double meanGray(const DatasetFrame& frame) {
  return cv::mean(frame.gray)[0];
}

TEST(VideoReader, DecodesFramesInAndOutOfOrder) {
  TempFolder folder;
  const auto video = folder / "clip.avi";
  if (!writeVideo(video)) GTEST_SKIP() << "this OpenCV build cannot write MJPG .avi files";
  test::writeText(folder / "clip.yaml", test::minimalCameraYaml(64, 48));
  ASSERT_EQ(detectDatasetFormat(video), DatasetFormat::kVideo);
  auto reader = openDataset(video);
  ASSERT_EQ(reader->info().frame_count, static_cast<std::size_t>(kFrames));
  EXPECT_NEAR(reader->info().fps, 10.0, 1e-6);
  EXPECT_NEAR(reader->timestamps()[3], 0.3, 1e-9);
  EXPECT_FALSE(reader->info().has_ground_truth);

  for (std::size_t i = 0; i < static_cast<std::size_t>(kFrames); ++i) {
    const DatasetFrame frame = reader->load(i);
    EXPECT_EQ(frame.color.type(), CV_8UC3);
    EXPECT_NEAR(meanGray(frame), 30.0 * static_cast<double>(i + 1), 3.0) << "frame " << i;
  }
  EXPECT_NEAR(meanGray(reader->load(1)), 60.0, 3.0);   // backwards: re-opens
  EXPECT_NEAR(meanGray(reader->load(4)), 150.0, 3.0);  // forwards: skips
  EXPECT_NEAR(meanGray(reader->load(0)), 30.0, 3.0);
  EXPECT_THROW(reader->load(kFrames), DatasetError);
}

TEST(VideoReader, CameraFileNamedAfterTheWholeFileNameAndMissingCamera) {
  TempFolder folder;
  const auto video = folder / "clip.avi";
  if (!writeVideo(video)) GTEST_SKIP() << "this OpenCV build cannot write MJPG .avi files";
  try {
    openDataset(video);
    FAIL() << "expected an error without a camera";
  } catch (const DatasetError& e) {
    EXPECT_NE(std::string(e.what()).find("--camera"), std::string::npos) << e.what();
  }
  test::writeText(folder / "clip.avi.yaml", test::minimalCameraYaml(64, 48));
  EXPECT_EQ(openDataset(video)->camera().width(), 64);
}

TEST(VideoReader, NotAVideoIsAClearError) {
  TempFolder folder;
  test::writeText(folder / "clip.avi", "this is not a video");
  test::writeText(folder / "clip.yaml", test::minimalCameraYaml(64, 48));
  try {
    openDataset(folder / "clip.avi");
    FAIL() << "expected an error";
  } catch (const DatasetError& e) {
    EXPECT_NE(std::string(e.what()).find("clip.avi"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace edgeslam
