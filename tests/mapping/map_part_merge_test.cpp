// Two parts of one map that share nothing (two clients' keyframes before a loop joins them): the
// merge moves the part without the map's origin onto the other whole, rigidly or with a scale,
// and joins the spanning trees.
#include "mapping/map_part_merge.h"

#include <gtest/gtest.h>

#include <vector>

#include "corridor_map.h"

namespace edgeslam {
namespace {

constexpr int kPointsPerKeyFrame = 40;

// A straight walk: keyframe k at x = 0.1 k looking down +z at points 3 m ahead.
SE3d truePose(int k) {
  return SE3d(Eigen::Quaterniond::Identity(), Eigen::Vector3d(-0.1 * k, 0.0, 0.0));
}
Eigen::Vector3d truePoint(int k, int i) {
  return Eigen::Vector3d(0.1 * k + 0.01 * i, 0.02 * (i % 7), 3.0 + 0.05 * (i % 5));
}

struct TwoParts {
  PinholeCamera camera = test::syntheticCamera();
  Map map{1};
  std::vector<KeyFrame*> first;   // in the map's own frame (holds the origin)
  std::vector<KeyFrame*> second;  // in a frame of its own: world_second = frame * world_first
  std::vector<std::vector<MapPoint*>> points_of_second;
  Sim3d frame;

  explicit TwoParts(const Sim3d& second_frame) : frame(second_frame) {
    MutexLock lock(map.updateMutex());
    const auto addPart = [&](int from, int to, const Sim3d& world,
                             std::vector<KeyFrame*>& keyframes) REQUIRES(map.updateMutex()) {
      std::vector<MapPoint*> previous;
      for (int k = from; k < to; ++k) {
        const SE3d pose = (Sim3d(truePose(k)) * world.inverse()).toSE3();
        KeyFrame* kf = map.createKeyFrame(static_cast<std::size_t>(k), 0.1 * k,
                                          test::corridorFeatures(camera, kPointsPerKeyFrame), pose);
        std::vector<MapPoint*> own;
        for (int i = 0; i < kPointsPerKeyFrame; ++i) {
          // Half of each keyframe's points are the previous keyframe's: a covisible chain.
          MapPoint* p = i < kPointsPerKeyFrame / 2 && !previous.empty()
                            ? previous[static_cast<std::size_t>(i + kPointsPerKeyFrame / 2)]
                            : map.createMapPoint(world * truePoint(k, i), kf);
          map.addObservation(p, kf, static_cast<std::size_t>(i));
          own.push_back(p);
        }
        map.updateConnections(kf);
        keyframes.push_back(kf);
        if (&keyframes == &second) points_of_second.push_back(own);
        previous = own;
      }
    };
    addPart(0, 6, Sim3d::identity(), first);
    addPart(10, 16, frame, second);
    map.takeChanges();
  }
};

Sim3d someFrame(double scale) {
  return Sim3d(
      scale,
      Eigen::Quaterniond(Eigen::AngleAxisd(0.7, Eigen::Vector3d(0.2, 1.0, 0.1).normalized())),
      Eigen::Vector3d(1.5, -0.4, 2.0));
}

void expectSecondPartInTheFirstsFrame(TwoParts& parts) REQUIRES(parts.map.updateMutex()) {
  for (std::size_t k = 0; k < parts.second.size(); ++k) {
    const KeyFrame* kf = parts.second[k];
    const SE3d expected = truePose(static_cast<int>(kf->frameIndex()));
    EXPECT_LT((kf->cameraCenter() - expected.inverse().translation()).norm(), 1e-9) << k;
    EXPECT_LT(Eigen::AngleAxisd(kf->pose().rotation() * expected.rotation().inverse()).angle(),
              1e-9);
    for (int i = kPointsPerKeyFrame / 2; i < kPointsPerKeyFrame; ++i) {
      const MapPoint* p = parts.points_of_second[k][static_cast<std::size_t>(i)];
      // In its keyframe's camera the point is where it truly is, up to the part's scale.
      const Eigen::Vector3d seen = kf->pose() * p->position();
      const Eigen::Vector3d truly = expected * truePoint(static_cast<int>(kf->frameIndex()), i);
      EXPECT_LT((seen.normalized() - truly.normalized()).norm(), 1e-9);
    }
  }
}

TEST(MapPartMerge, ALoopFromTheSecondPartMovesItOntoTheFirst) {
  for (double scale : {1.0, 0.6}) {  // RGB-D (SE(3)) and monocular (Sim(3))
    TwoParts parts(someFrame(scale));
    MutexLock lock(parts.map.updateMutex());
    EXPECT_FALSE(connectedPart(parts.second.back()).contains(parts.first.back()));
    VerifiedLoop loop;
    loop.current = parts.second.back();
    loop.loop = parts.first.back();
    // The loop's view: the current camera from the first part's world, in the units the current
    // camera's points have (the second part's scale).
    loop.S_cw = Sim3d(scale, Eigen::Quaterniond::Identity(), Eigen::Vector3d::Zero()) *
                Sim3d(truePose(static_cast<int>(loop.current->frameIndex())));
    const MapPartMerge merge = mergeSeparateParts(parts.map, loop);
    EXPECT_TRUE(merge.merged);
    EXPECT_TRUE(merge.moved_current_side);
    EXPECT_EQ(merge.keyframes_moved, parts.second.size());
    expectSecondPartInTheFirstsFrame(parts);
    // The first part did not move.
    EXPECT_LT((parts.first[3]->cameraCenter() - truePose(3).inverse().translation()).norm(), 1e-12);
    // One spanning tree, rooted at the map's origin.
    for (KeyFrame* kf : parts.second) {
      const KeyFrame* root = kf;
      while (root->parent() != nullptr) root = root->parent();
      EXPECT_EQ(root, parts.map.originKeyFrame());
    }
    EXPECT_TRUE(connectedPart(parts.second.front()).contains(parts.first.front()));
    EXPECT_EQ(loop.current->parent(), loop.loop);
    // The loop's relation now holds where the current keyframe is.
    EXPECT_LT((loop.S_cw.toSE3().translation() - loop.current->pose().translation()).norm(), 1e-9);
    // A second loop across the seam is an ordinary one.
    EXPECT_FALSE(mergeSeparateParts(parts.map, loop).merged);
  }
}

TEST(MapPartMerge, ALoopFromThePartWithTheOriginMovesTheOtherPart) {
  TwoParts parts(someFrame(1.0));
  MutexLock lock(parts.map.updateMutex());
  VerifiedLoop loop;
  loop.current = parts.first.back();
  loop.loop = parts.second.front();
  // The current keyframe's pose as the loop side sees it: in the second part's frame.
  const SE3d current_truth = truePose(static_cast<int>(loop.current->frameIndex()));
  loop.S_cw = Sim3d(current_truth) * parts.frame.inverse();
  const MapPartMerge merge = mergeSeparateParts(parts.map, loop);
  EXPECT_TRUE(merge.merged);
  EXPECT_FALSE(merge.moved_current_side);
  expectSecondPartInTheFirstsFrame(parts);
  EXPECT_EQ(loop.loop->parent(), loop.current);
  // S_cw is re-expressed in the frame the map keeps: the current keyframe's own pose.
  EXPECT_LT((loop.S_cw.toSE3().translation() - current_truth.translation()).norm(), 1e-9);
}

}  // namespace
}  // namespace edgeslam
