// Degenerate input that looks valid, made from real 7-Scenes frames: a camera that does not move
// (one frame repeated), a camera that only rotates (one frame warped by K R K^-1), blank and
// overexposed frames. The tracker must not build a map from them, must not report a pose for a
// frame it cannot see, and must say why (TrackingDiagnostics). Real motion on the same frames
// builds a map, so each test can fail.
#include <gtest/gtest.h>

#include <memory>
#include <vector>

#include "client/tracker.h"
#include "features/frame_features_builder.h"
#include "features/orb_extractor.h"
#include "io/dataset.h"
#include "support/shared_data.h"
#include "synth/degenerate_frames.h"

namespace edgeslam {
namespace {

constexpr const char* kKitchen = "datasets/7scenes-redkitchen-1000";

class DegenerateInput : public ::testing::Test {
 protected:
  void SetUp() override {
    EDGESLAM_REQUIRE_SHARED(kKitchen);
    reader_ = openDataset(test::sharedPath(kKitchen));
  }

  std::unique_ptr<Tracker> makeTracker(Sensor sensor) {
    TrackerOptions options;
    options.sensor = sensor;
    return std::make_unique<Tracker>(map_, reader_->camera(), options, nullptr);
  }

  TrackResult track(Tracker& tracker, std::size_t index, const cv::Mat& gray,
                    const cv::Mat& depth = {}) {
    return tracker.track(index, static_cast<double>(index) / 30.0,
                         buildFrameFeatures(gray, depth, reader_->camera(), extractor_));
  }

  std::unique_ptr<DatasetReader> reader_;
  OrbExtractor extractor_;
  Map map_;
};

TEST_F(DegenerateInput, StillCameraBuildsNoMapAndSaysLowParallax) {
  auto tracker = makeTracker(Sensor::kMonocular);
  const cv::Mat still = reader_->load(100).gray;
  for (std::size_t i = 0; i < 20; ++i) {
    const TrackResult r = track(*tracker, i, still);
    EXPECT_FALSE(r.T_cw.has_value()) << "frame " << i;
  }
  const TrackingDiagnostics& d = tracker->diagnostics();
  EXPECT_EQ(tracker->state(), TrackingState::kNotInitialized);
  EXPECT_FALSE(d.initialized_at_frame.has_value());
  EXPECT_EQ(d.frames_without_map, 20u);
  EXPECT_EQ(d.refused(InitRefusal::kLowParallax), 19u) << d.last_refusal;
  MutexLock lock(map_.updateMutex());
  EXPECT_EQ(map_.keyFrameCount(), 0u);
}

TEST_F(DegenerateInput, PureRotationBuildsNoMap) {
  auto tracker = makeTracker(Sensor::kMonocular);
  const cv::Mat first = reader_->load(100).gray;
  const Eigen::Matrix3d K = reader_->camera().K();
  std::size_t refused = 0;
  for (std::size_t i = 0; i < 25; ++i) {
    const cv::Mat view = rotatedView(first, K, panRotation(0.4 * static_cast<double>(i)));
    const TrackResult r = track(*tracker, i, view);
    EXPECT_FALSE(r.T_cw.has_value())
        << "frame " << i << ": " << tracker->diagnostics().last_refusal;
  }
  const TrackingDiagnostics& d = tracker->diagnostics();
  for (std::size_t n : d.refusals) refused += n;
  EXPECT_FALSE(d.initialized_at_frame.has_value());
  EXPECT_EQ(refused, 24u);
  // Rotation leaves no parallax: that is the reason given, not some other failure.
  EXPECT_GE(d.refused(InitRefusal::kLowParallax), 20u) << d.last_refusal;
}

TEST_F(DegenerateInput, RealMotionOnTheSameFramesBuildsAMap) {
  auto tracker = makeTracker(Sensor::kMonocular);
  for (std::size_t i = 0; i < 60; ++i) track(*tracker, i, reader_->load(i).gray);
  const TrackingDiagnostics& d = tracker->diagnostics();
  ASSERT_TRUE(d.initialized_at_frame.has_value()) << d.last_refusal;
  EXPECT_EQ(d.initializations, 1u);
  EXPECT_EQ(d.frames_without_map, *d.initialized_at_frame + 1);
  EXPECT_EQ(tracker->state(), TrackingState::kOk);
}

TEST_F(DegenerateInput, BlankAndOverexposedFramesWaitForFeatures) {
  auto tracker = makeTracker(Sensor::kMonocular);
  const cv::Mat real = reader_->load(100).gray;
  for (std::size_t i = 0; i < 10; ++i) track(*tracker, i, blankLike(real, 128));
  for (std::size_t i = 10; i < 20; ++i) track(*tracker, i, overexposed(real, 8.0));
  const TrackingDiagnostics& d = tracker->diagnostics();
  EXPECT_FALSE(d.initialized_at_frame.has_value());
  EXPECT_EQ(d.refused(InitRefusal::kTooFewFeatures), 20u) << d.last_refusal;
}

TEST_F(DegenerateInput, BlankStretchAfterTheMapIsLostToTooFewFeaturesAndRecovers) {
  auto tracker = makeTracker(Sensor::kMonocular);
  std::size_t index = 0;
  for (; index < 60; ++index) track(*tracker, index, reader_->load(index).gray);
  ASSERT_EQ(tracker->state(), TrackingState::kOk) << tracker->diagnostics().last_refusal;
  const cv::Mat blank = blankLike(reader_->load(0).gray, 200);
  for (std::size_t i = 0; i < 5; ++i, ++index) {
    const TrackResult r = track(*tracker, index, blank);
    EXPECT_FALSE(r.T_cw.has_value()) << "blank frame " << index << " got a pose";
    EXPECT_EQ(r.state, TrackingState::kLost);
  }
  // The camera kept moving while the view was blank: frames resume 5 frames on.
  bool back = false;
  for (std::size_t i = 0; i < 30 && !back; ++i, ++index) {
    back = track(*tracker, index, reader_->load(index).gray).T_cw.has_value();
  }
  const TrackingDiagnostics& d = tracker->diagnostics();
  EXPECT_TRUE(back);
  EXPECT_EQ(d.lostTo(LostCause::kTooFewFeatures), 5u);
}

TEST_F(DegenerateInput, RgbdWaitsForFeaturesAndDepth) {
  auto tracker = makeTracker(Sensor::kRgbd);
  const DatasetFrame frame = reader_->load(100);
  ASSERT_FALSE(frame.depth.empty());
  track(*tracker, 0, overexposed(frame.gray, 8.0), frame.depth);
  track(*tracker, 1, frame.gray, cv::Mat::zeros(frame.depth.size(), frame.depth.type()));
  const TrackingDiagnostics& d = tracker->diagnostics();
  EXPECT_FALSE(d.initialized_at_frame.has_value());
  EXPECT_EQ(d.refused(InitRefusal::kTooFewFeatures), 1u);
  EXPECT_EQ(d.refused(InitRefusal::kTooFewDepthPoints), 1u);
  // The same frame with its depth: a map at once (depth gives the scale a still camera lacks).
  EXPECT_TRUE(track(*tracker, 2, frame.gray, frame.depth).T_cw.has_value());
  EXPECT_EQ(tracker->diagnostics().initialized_at_frame, 2u);
}

}  // namespace
}  // namespace edgeslam
