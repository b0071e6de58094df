// Kidnapping: the camera is blinded for a while (featureless frames) and comes back elsewhere on
// its path (RGB-D: ahead, where the map barely reaches; monocular: back to a mapped place);
// tracking must find itself again in the same map, by bag of words. A short dropout, after which
// the camera is where its motion has taken it, is bridged by the motion prediction instead.
#include <gtest/gtest.h>

#include "eval/ate.h"
#include "features/orb_extractor.h"
#include "io/dataset.h"
#include "modes/local_slam.h"
#include "place/vocabulary_training.h"
#include "support/shared_data.h"

namespace edgeslam {
namespace {

constexpr const char* kSequence = "datasets/7scenes-redkitchen-1000";

std::shared_ptr<const Vocabulary> smallVocabulary(DatasetReader& reader) {
  OrbExtractor extractor(OrbExtractorOptions{});
  std::vector<cv::Mat> descriptors;
  for (std::size_t i = 0; i < reader.info().frame_count; i += 12) {
    descriptors.push_back(extractor.extract(reader.load(i).gray).descriptors);
  }
  VocabularyTrainingOptions options;
  options.branching = 10;
  options.levels = 4;
  options.threads = 0;
  return std::make_shared<const Vocabulary>(trainVocabulary(descriptors, options));
}

struct KidnapOutcome {
  std::size_t frames_to_recover = 0;
  bool recovered = false;
  std::size_t relocalizations = 0;
  std::size_t recoveries = 0;  // by the motion prediction
  std::size_t resets = 0;
  double ate_after_return_m = 0.0;
};

// Frames [0, 150), then `blank_frames` blank frames, then the camera returns at frame
// `return_at`.
KidnapOutcome kidnap(Sensor sensor, std::size_t return_at, int blank_frames = 20) {
  auto reader = openDataset(test::sharedPath(kSequence));
  SlamOptions options = defaultSlamOptions(reader->camera(), sensor);
  options.backend.threaded = false;
  options.tracker.vocabulary = smallVocabulary(*reader);
  LocalSlam slam(reader->camera(), options);

  std::size_t index = 0;
  double t = 0.0;
  for (std::size_t i = 0; i < 150; ++i, ++index, t += 1.0 / 30) {
    const DatasetFrame f = reader->load(i);
    slam.process(index, t, f.gray, f.depth);
  }
  const DatasetFrame first = reader->load(0);
  const cv::Mat blank(first.gray.size(), first.gray.type(), cv::Scalar(128));
  const cv::Mat no_depth =
      first.depth.empty() ? cv::Mat() : cv::Mat::zeros(first.depth.size(), first.depth.type());
  for (int k = 0; k < blank_frames; ++k, ++index, t += 1.0 / 30) {
    const TrackResult r = slam.process(index, t, blank, no_depth);
    EXPECT_NE(r.state, TrackingState::kOk) << "tracked a blank frame";
  }
  KidnapOutcome out;
  Trajectory ground_truth;
  std::vector<double> returned_stamps;
  for (std::size_t i = return_at; i < return_at + 60; ++i, ++index, t += 1.0 / 30) {
    const DatasetFrame f = reader->load(i);
    const TrackResult r = slam.process(index, t, f.gray, f.depth);
    ground_truth.push_back({t, *f.ground_truth});
    if (r.state == TrackingState::kOk && !out.recovered) {
      out.recovered = true;
      out.frames_to_recover = i - return_at;
    }
  }
  slam.finish();
  out.relocalizations = slam.relocalizations();
  out.recoveries = slam.trackingRecoveries();
  out.resets = slam.mapResets();
  // The poses after the return must agree with the ground truth of the whole run's frame.
  Trajectory before_gt;
  for (std::size_t i = 0; i < 150; ++i) {
    before_gt.push_back({i / 30.0, *reader->load(i).ground_truth});
  }
  before_gt.insert(before_gt.end(), ground_truth.begin(), ground_truth.end());
  const AteResult ate =
      computeAte(associateByTimestamp(before_gt, slam.trajectoryFinal()),
                 sensor == Sensor::kMonocular ? AlignMode::kSim3 : AlignMode::kSe3);
  out.ate_after_return_m = ate.translation.rmse;
  return out;
}

void expectRecovered(const KidnapOutcome& r, double ate_bound_m) {
  EXPECT_TRUE(r.recovered);
  EXPECT_LE(r.frames_to_recover, 30u);
  EXPECT_GE(r.relocalizations, 1u);
  EXPECT_EQ(r.resets, 0u);  // found itself in the same map, not a new one
  EXPECT_LT(r.ate_after_return_m, ate_bound_m);
}

TEST(Relocalization, RgbdFindsItselfAfterBeingBlindedAndMoved) {
  EDGESLAM_REQUIRE_SHARED(kSequence);
  expectRecovered(kidnap(Sensor::kRgbd, 200), 0.08);
}

TEST(Relocalization, MonocularFindsItselfAfterBeingBlindedAndBroughtBack) {
  EDGESLAM_REQUIRE_SHARED(kSequence);
  expectRecovered(kidnap(Sensor::kMonocular, 100), 0.10);
}

TEST(Relocalization, MonocularBridgesAShortDropoutByItsMotionPrediction) {
  EDGESLAM_REQUIRE_SHARED(kSequence);
  // Four frames lost (150-153 blank), then the camera is where it would have been.
  const KidnapOutcome r = kidnap(Sensor::kMonocular, 154, 4);
  EXPECT_TRUE(r.recovered);
  EXPECT_LE(r.frames_to_recover, 1u);
  EXPECT_EQ(r.recoveries, 1u);
  EXPECT_EQ(r.relocalizations, 0u);
  EXPECT_EQ(r.resets, 0u);
  EXPECT_LT(r.ate_after_return_m, 0.10);
}

}  // namespace
}  // namespace edgeslam
