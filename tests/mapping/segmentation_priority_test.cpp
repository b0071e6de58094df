// On the edge's one core, a session that segments keyframes runs its mapping thread nicer than
// segmentation, so that masks reach the client first; without segmentation mapping keeps the
// caller's priority.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <memory>

#include "map/map_replication.h"
#include "map/synthetic_views.h"
#include "server/edge_map_session.h"
#include "util/thread_priority.h"

namespace edgeslam {
namespace {

using test::poseAt;

// Finds nothing; the session only needs one to exist.
class NothingSegmenter : public Segmenter {
 public:
  Segmentation segment(const cv::Mat& image) override {
    Segmentation s;
    s.movable_mask = cv::Mat1b::zeros(image.size());
    s.label_image = cv::Mat1b::zeros(image.size());
    return s;
  }
  void setNmsThreshold(float nm) override { nm_ = nm; }
  float nmsThreshold() const override { return nm_; }
  void setScoreThreshold(float score) override { score_ = score; }
  float scoreThreshold() const override { return score_; }
  std::string backendName() const override { return "nothing"; }

 private:
  float nm_ = 0.8f, score_ = 0.3f;
};

// The nice value of the thread that mapped the session's first keyframe.
int niceOfMappingThread(std::shared_ptr<Segmenter> segmenter) {
  test::SyntheticScene scene(150, 5);
  Map client(1);
  KeyFrameUpload upload;
  {
    MutexLock lock(client.updateMutex());
    KeyFrame* keyframe = scene.addKeyFrame(client, scene.view(poseAt({0, 0, 0}), 0, true), 0, true);
    upload.sequence = 1;
    upload.keyframe = keyFrameRecord(*keyframe);
    for (MapPoint* p : keyframe->goodPoints()) upload.new_points.push_back(mapPointRecord(*p));
  }

  EdgeMapSessionOptions options;
  options.backend.segmenter = std::move(segmenter);
  std::atomic<int> mapping_nice{-100};
  {
    EdgeMapSession session(scene.camera(), Sensor::kRgbd, options, [&](MapSlice slice) {
      if (slice.processed_keyframe != kInvalidId) mapping_nice = currentThreadNice();
    });
    session.onKeyFrame(upload);
    session.finish();
  }
  return mapping_nice;
}

TEST(EdgeSegmentationPriority, MappingYieldsToSegmentationOnlyWhenTheSessionSegments) {
  const int own = currentThreadNice();
  const int without = niceOfMappingThread(nullptr);
  const int with = niceOfMappingThread(std::make_shared<NothingSegmenter>());
  EXPECT_EQ(without, own);
  const int expected =
      std::min(19, own + EdgeMapSessionOptions{}.backend.thread_nice_when_segmenting);
  EXPECT_EQ(with, expected);
}

}  // namespace
}  // namespace edgeslam
