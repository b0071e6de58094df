// Semantic culling on the two kinds of generated sequence that broke it when they were first tried
// (issue "Semantics that hold on sequences they were not tuned on"), as a user runs them:
// - someone close to the camera crossing it at ~30 px a frame (RGB-D): the keyframe's mask was
//   searched for too near where the keyframe saw them, was not found, and stayed behind (mask IoU
//   0.24 at --fast, 0.37 at --realtime; now 0.74 / 0.79 on the 600 frames it was found on);
// - a monocular map begun while someone walked by (mono): it made a keyframe a frame, was lost
//   when that person's points were culled, and was never relocalised (7 of 240 frames tracked).
// - a monocular map begun on the first frames, two people in view (mono): the people were
//   triangulated with the scene and their points erased once the mask came, leaving ~60 tracked
//   points; the map was lost at frame 86 for good (110 of 240 tracked, mask IoU 0.41, ATE 8.9 cm).
// All at --fast, so that the figures do not depend on the host's speed.
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

namespace fs = std::filesystem;
constexpr const char* kSequence = "datasets/7scenes-redkitchen-1000";

fs::path generate(const std::string& name, const std::string& options) {
  const fs::path out = test::processTempFolder(name);
  fs::remove_all(out);
  const auto r =
      test::runEdgeslam("synth-dynamic --dataset " + test::sharedPath(kSequence).string() +
                        " --out " + out.string() + " " + options);
  EXPECT_EQ(r.exit_code, 0) << r.output;
  return out;
}

nlohmann::json run(const fs::path& dataset, const std::string& sensor, const std::string& name) {
  const fs::path out = test::processTempFolder(name);
  const auto r =
      test::runEdgeslam("run --dataset " + dataset.string() + " --mode local --sensor " + sensor +
                        " --semantic on --fast --vocab none --out " + out.string());
  EXPECT_EQ(r.exit_code, 0) << r.output;
  std::ifstream in(out / "metrics.json");
  if (!in) return {};
  return nlohmann::json::parse(in);
}

void requireData() {
  EDGESLAM_REQUIRE_SHARED(kSequence);
  EDGESLAM_REQUIRE_SHARED("datasets/people");
  EDGESLAM_REQUIRE_SHARED("models");
}

TEST(SemanticUnseenMotion, AMaskFollowsSomeoneCrossingCloseToTheCamera) {
  requireData();
  const fs::path dataset =
      generate("close", "--frames 200-439 --seed 77 --num-people 1 --coverage 35");
  const nlohmann::json m = run(dataset, "rgbd", "close-run");
  ASSERT_TRUE(m.contains("semantic")) << m.dump(2);
  const auto& s = m["semantic"];
  ASSERT_FALSE(s["mask_iou_median"].is_null()) << s.dump(2);
  std::printf(
      "close person, RGB-D --fast: mask IoU %.3f over %d frames, culled precision %.2f "
      "recall %.2f, mask age median %s\n",
      s["mask_iou_median"].get<double>(), s["mask_iou_frames"].get<int>(),
      s["culled_precision"].get<double>(), s["culled_recall"].get<double>(),
      s["mask_age_frames"]["median"].dump().c_str());
  EXPECT_GT(s["mask_iou_median"].get<double>(), 0.6);  // 0.2-0.3 when the mask stayed behind
  EXPECT_GT(s["culled_recall"].get<double>(), 0.6);
  EXPECT_GT(s["culled_precision"].get<double>(), 0.5);
  // Every tracked frame's mask was transferred from a keyframe, some frames after it.
  EXPECT_GT(s["mask_source"]["transferred"].get<int>(), 200);
  EXPECT_GE(s["mask_age_frames"]["median"].get<int>(), 1);
  EXPECT_EQ(m["tracked"].get<int>(), 240);
}

TEST(SemanticUnseenMotion, AMonocularMapBegunOnSomeoneWalkingByStartsAgain) {
  requireData();
  const fs::path dataset =
      generate("walker", "--frames 60-299 --seed 1001 --num-people 1 --coverage 10");
  const nlohmann::json m = run(dataset, "mono", "walker-run");
  ASSERT_TRUE(m.contains("semantic")) << m.dump(2);
  std::printf("mono map begun on a walker: %d of 240 tracked, %d resets, mask IoU %s\n",
              m["tracked"].get<int>(), m["map_resets"].get<int>(),
              m["semantic"]["mask_iou_median"].dump().c_str());
  EXPECT_GE(m["tracked"].get<int>(), 180);  // 7 when the first map was kept
  ASSERT_FALSE(m["semantic"]["mask_iou_median"].is_null());
  EXPECT_GT(m["semantic"]["mask_iou_median"].get<double>(), 0.6);
}

// Two people in view from the first frame (frames 375-614, seed 1011), run at --fast.
struct TwoWalkersRun {
  nlohmann::json metrics;
  double ate_cm = 0.0;
};

TwoWalkersRun runTwoWalkers(const std::string& sensor) {
  const fs::path dataset = generate("two-walkers-" + sensor,
                                    "--frames 375-614 --seed 1011 --num-people 2 --coverage 10");
  TwoWalkersRun out{run(dataset, sensor, "two-walkers-" + sensor + "-run"), 0.0};
  const nlohmann::json& m = out.metrics;
  if (!m.contains("semantic") || !m.contains("ate_final")) {
    ADD_FAILURE() << m.dump(2);
    return out;
  }
  out.ate_cm = 100.0 * m["ate_final"]["rmse_m"].get<double>();
  std::printf("%s, two people from the first frame: %d of 240 tracked, ATE %.2f cm, mask IoU %s\n",
              sensor.c_str(), m["tracked"].get<int>(), out.ate_cm,
              m["semantic"]["mask_iou_median"].dump().c_str());
  return out;
}

TEST(SemanticUnseenMotion, AMonocularMapIsBegunOnMaskedFrames) {
  requireData();
  const TwoWalkersRun r = runTwoWalkers("mono");
  if (HasFailure()) return;
  const auto& s = r.metrics["semantic"];
  // The first frame was segmented before any keyframe existed: every later frame had a mask.
  EXPECT_LE(s["mask_source"]["none"].get<int>(), 1);
  EXPECT_LT(r.ate_cm, 6.0);  // 2.8 on the source frames; 8.9 when the map began on the people
  EXPECT_GT(s["mask_iou_median"].get<double>(), 0.6);
}

TEST(SemanticUnseenMotion, AnRgbdMapIsBegunOnAMaskedFrame) {
  requireData();
  const TwoWalkersRun r = runTwoWalkers("rgbd");
  if (HasFailure()) return;
  const auto& s = r.metrics["semantic"];
  // The map's first frame waited for its own mask (before: tracked without one, its people in
  // the first keyframe).
  EXPECT_EQ(s["mask_source"]["none"].get<int>(), 0);
  EXPECT_EQ(r.metrics["tracked"].get<int>(), 240);
  EXPECT_LT(r.ate_cm, 8.0);  // 4.2 on the source frames; 5.2-6.2 measured (5.9 before, unmasked)
  EXPECT_GT(s["mask_iou_median"].get<double>(), 0.6);
}

}  // namespace
}  // namespace edgeslam
