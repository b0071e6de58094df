// The mapping back end that local mode and every edge session compose: its options are checked in
// one place (bad values fail with one line naming the field, whichever mode brings them), and it
// maps, segments and reports through its hooks the same way for both.
#include "mapping/mapping_backend.h"

#include <gtest/gtest.h>

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "map/synthetic_views.h"
#include "modes/local_slam.h"
#include "server/edge_map_session.h"

namespace edgeslam {
namespace {

struct BadValue {
  std::string field;
  std::function<void(MappingBackendOptions&)> set;
};

// The message of the std::invalid_argument that check() throws, or "" when it throws none.
std::string checkMessage(const MappingBackendOptions& options) {
  try {
    options.check();
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return {};
}

TEST(MappingBackendOptions, DefaultsOfBothModesPass) {
  EXPECT_EQ(checkMessage(MappingBackendOptions{}), "");
  EXPECT_EQ(checkMessage(edgeSessionBackendOptions()), "");
  EXPECT_EQ(checkMessage(EdgeMapSessionOptions{}.backend), "");
  EXPECT_EQ(checkMessage(SlamOptions{}.backend), "");
}

TEST(MappingBackendOptions, BadValuesFailWithOneLineNamingTheField) {
  const std::vector<BadValue> bad = {
      {"thread_nice", [](auto& o) { o.thread_nice = 20; }},
      {"thread_nice", [](auto& o) { o.thread_nice = -1; }},
      {"thread_nice_when_segmenting", [](auto& o) { o.thread_nice_when_segmenting = 40; }},
      {"movable_point_erode_px", [](auto& o) { o.movable_point_erode_px = -2; }},
      {"mapper.max_queue", [](auto& o) { o.mapper.max_queue = 0; }},
      {"mapper.triangulation_ratio", [](auto& o) { o.mapper.triangulation_ratio = 1.5f; }},
      {"mapper.triangulation_neighbours_depth",
       [](auto& o) { o.mapper.triangulation_neighbours_depth = 0; }},
      {"mapper.min_triangulation_parallax_deg",
       [](auto& o) { o.mapper.min_triangulation_parallax_deg = 0.0; }},
      {"mapper.redundant_ratio", [](auto& o) { o.mapper.redundant_ratio = 0.0; }},
      {"mapper.revisit_max_angle_deg", [](auto& o) { o.mapper.revisit_max_angle_deg = 270.0; }},
      {"loop_closer.global_ba_iterations", [](auto& o) { o.loop_closer.global_ba_iterations = 0; }},
      {"loop_closer.detector.consistency_required",
       [](auto& o) { o.loop_closer.detector.consistency_required = 0; }},
      {"loop_closer.verifier.min_sim3_inliers",
       [](auto& o) { o.loop_closer.verifier.min_sim3_inliers = 2; }},
      {"loop_closer.correction.fuse_radius",
       [](auto& o) { o.loop_closer.correction.fuse_radius = -1.f; }},
  };
  for (const BadValue& b : bad) {
    MappingBackendOptions options;
    b.set(options);
    const std::string message = checkMessage(options);
    EXPECT_NE(message.find(b.field + " must be"), std::string::npos) << message;
    EXPECT_EQ(message.rfind("mapping back end: ", 0), 0u) << message;
    EXPECT_NE(message.find("(got "), std::string::npos) << message;
    EXPECT_EQ(message.find('\n'), std::string::npos) << message;
  }
}

TEST(MappingBackendOptions, LoopClosingOptionsMatterOnlyWithLoopClosing) {
  MappingBackendOptions options;
  options.loop_closer.global_ba_iterations = 0;
  options.loop_closing = false;
  EXPECT_EQ(checkMessage(options), "");
  options.loop_closing = true;
  EXPECT_NE(checkMessage(options), "");
}

TEST(MappingBackendOptions, LoopClosingWithAnEmptyVocabularyFails) {
  MappingBackendOptions options;
  options.vocabulary = std::make_shared<const Vocabulary>();
  EXPECT_EQ(checkMessage(options),
            "mapping back end: loop closing needs a trained vocabulary (this one is empty)");
  options.loop_closing = false;
  EXPECT_EQ(checkMessage(options), "");
}

// The one check is where the back end is made, so a bad value fails before any thread starts in
// local mode and in an edge session alike.
TEST(MappingBackendOptions, BothModesRefuseBadOptionsAtConstruction) {
  const PinholeCamera camera = test::syntheticCamera();
  MappingBackendOptions bad;
  bad.mapper.max_queue = 0;
  Map map;
  EXPECT_THROW(MappingBackend(map, camera, Sensor::kRgbd, bad), std::invalid_argument);
  EdgeMapSessionOptions edge;
  edge.backend = bad;
  EXPECT_THROW(EdgeMapSession(camera, Sensor::kRgbd, edge, {}), std::invalid_argument);
  SlamOptions local = defaultSlamOptions(camera, Sensor::kRgbd);
  local.backend = bad;
  EXPECT_THROW(LocalSlam(camera, local), std::invalid_argument);
}

cv::Size imageSize(const PinholeCamera& camera) {
  return {camera.width(), camera.height()};
}

// Labels the whole image as one movable instance.
class EverythingMovable : public Segmenter {
 public:
  Segmentation segment(const cv::Mat& image) override {
    Segmentation s;
    s.movable_mask = cv::Mat1b(image.size(), 255);
    s.label_image = cv::Mat1b(image.size(), 1);
    return s;
  }
  void setNmsThreshold(float) override {}
  float nmsThreshold() const override { return 0.8f; }
  void setScoreThreshold(float) override {}
  float scoreThreshold() const override { return 0.3f; }
  std::string backendName() const override { return "everything"; }
};

// Unthreaded: a keyframe is segmented (its points on the mask erased) when it is handed over, and
// mapped, with the hook told, only by processAll().
TEST(MappingBackend, UnthreadedSegmentsAndMapsOnTheCallersThreadWithItsHooks) {
  test::SyntheticScene scene(150, 7);
  Map map;
  MappingBackendOptions options;
  options.threaded = false;
  options.segmenter = std::make_shared<EverythingMovable>();
  std::vector<KeyFrameId> mapped;
  std::vector<KeyFrameId> segmented;
  MappingBackendHooks hooks;
  hooks.keyframe_mapped = [&](KeyFrame* keyframe) { mapped.push_back(keyframe->id()); };
  hooks.keyframe_segmented = [&](KeyFrameSegmentationResult result) {
    segmented.push_back(result.keyframe);
    EXPECT_EQ(result.labels.size(), imageSize(scene.camera()));
  };
  MappingBackend backend(map, scene.camera(), Sensor::kRgbd, options, std::move(hooks));
  backend.start();
  EXPECT_EQ(backend.loopCloser(), nullptr);  // no vocabulary
  KeyFrame* keyframe = nullptr;
  std::size_t points = 0;
  {
    MutexLock lock(map.updateMutex());
    keyframe = scene.addKeyFrame(map, scene.view(test::poseAt({0, 0, 0}), 0, true), 0, true);
    points = map.pointCount();
  }
  ASSERT_GT(points, 50u);
  backend.insertKeyFrame(keyframe);
  backend.segment({keyframe->id(), 0,
                   cv::Mat(imageSize(scene.camera()), CV_8UC3, cv::Scalar::all(0)),
                   imageSize(scene.camera())});
  EXPECT_EQ(segmented, std::vector<KeyFrameId>{keyframe->id()});
  EXPECT_TRUE(mapped.empty());
  backend.processAll();
  EXPECT_EQ(mapped, std::vector<KeyFrameId>{keyframe->id()});
  backend.waitUntilIdle();
  const MappingBackendCounters counters = backend.counters();
  EXPECT_EQ(counters.keyframes_segmented, 1u);
  // Every keypoint lies on the mask but those within the erosion of the image's border.
  EXPECT_GT(counters.movable_points_erased, points / 2);
  EXPECT_EQ(backend.failure(), std::nullopt);
}

}  // namespace
}  // namespace edgeslam
