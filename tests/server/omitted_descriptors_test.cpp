// Keyframe uploads leave out the descriptors of keypoints whose point the edge has; the edge takes
// the point's representative descriptor for them, and a keypoint whose point vanished meanwhile
// keeps neither point nor a descriptor that could match.
#include "server/omitted_descriptors.h"

#include <gtest/gtest.h>

#include <map>
#include <stdexcept>

#include "map/map_replication.h"
#include "map/synthetic_views.h"
#include "server/edge_map_session.h"
#include "wire/wire_convert.h"

namespace edgeslam {
namespace {

using test::poseAt;

double hamming(const cv::Mat& a, const cv::Mat& b) {
  return cv::norm(a, b, cv::NORM_HAMMING);
}

// A second view of the scene whose keypoints name the first keyframe's points where they see the
// same scene point, as the decoder hands the record over: those rows zero and flagged.
struct SecondView {
  KeyFrameRecord record;
  std::vector<std::size_t> associated;  // keypoints naming a point of the first keyframe
};

SecondView secondView(test::SyntheticScene& scene, const test::SyntheticView& first_view,
                      const KeyFrame& first) {
  std::map<int, const MapPoint*> point_of_scene;
  for (std::size_t i = 0; i < first_view.scene_point.size(); ++i) {
    point_of_scene[first_view.scene_point[i]] = first.point(i);
  }
  const test::SyntheticView view = scene.view(poseAt({0.1, 0, 0}), 8, true);
  SecondView out;
  out.record.id = 99;
  out.record.T_cw = view.T_cw;
  out.record.features = featuresRecord(*view.features);
  const std::size_t n = view.scene_point.size();
  out.record.point_ids.assign(n, kInvalidId);
  out.record.features.descriptor_omitted.assign(n, false);
  for (std::size_t j = 0; j < n; ++j) {
    const auto it = point_of_scene.find(view.scene_point[j]);
    if (it == point_of_scene.end()) continue;
    out.record.point_ids[j] = it->second->id();
    out.record.features.descriptor_omitted[j] = true;
    out.record.features.descriptors.row(static_cast<int>(j)).setTo(0);
    out.associated.push_back(j);
  }
  return out;
}

TEST(OmittedDescriptors, RowsTakeThePointsDescriptorAndAVanishedPointsKeypointLosesItsPoint) {
  test::SyntheticScene scene(80, 3);
  Map map;
  MutexLock lock(map.updateMutex());
  const test::SyntheticView first_view = scene.view(poseAt({0, 0, 0}), 0, true);
  KeyFrame* first = scene.addKeyFrame(map, first_view, 0, true);
  SecondView second = secondView(scene, first_view, *first);
  ASSERT_GE(second.associated.size(), 20u);
  const std::size_t vanished_keypoint = second.associated[3];
  MapPoint* vanished = map.mapPoint(second.record.point_ids[vanished_keypoint]);
  const cv::Mat vanished_descriptor = vanished->descriptor().clone();
  map.erasePoint(vanished);

  const OmittedDescriptorFill fill = fillOmittedDescriptors(map, second.record);
  EXPECT_EQ(fill.filled, second.associated.size() - 1);
  ASSERT_EQ(fill.lost, std::vector<std::size_t>{vanished_keypoint});
  EXPECT_TRUE(second.record.features.descriptor_omitted.empty());
  for (const std::size_t j : second.associated) {
    const cv::Mat row = second.record.features.descriptors.row(static_cast<int>(j));
    if (j == vanished_keypoint) {
      EXPECT_EQ(second.record.point_ids[j], kInvalidId);
      EXPECT_GT(hamming(row, vanished_descriptor), 80.0);
      continue;
    }
    const MapPoint* point = map.mapPoint(second.record.point_ids[j]);
    ASSERT_NE(point, nullptr);
    EXPECT_EQ(hamming(row, point->descriptor()), 0.0) << j;
  }
}

TEST(OmittedDescriptors, FlagsThatContradictTheRecordAreRefused) {
  test::SyntheticScene scene(80, 3);
  Map map;
  MutexLock lock(map.updateMutex());
  const test::SyntheticView first_view = scene.view(poseAt({0, 0, 0}), 0, true);
  KeyFrame* first = scene.addKeyFrame(map, first_view, 0, true);
  const SecondView second = secondView(scene, first_view, *first);

  KeyFrameRecord short_flags = second.record;
  short_flags.features.descriptor_omitted.pop_back();
  EXPECT_THROW(fillOmittedDescriptors(map, short_flags), std::invalid_argument);

  KeyFrameRecord no_point = second.record;
  no_point.point_ids[second.associated.front()] = kInvalidId;
  try {
    fillOmittedDescriptors(map, no_point);
    ADD_FAILURE() << "filled";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("names no map point"), std::string::npos) << e.what();
  }
}

// The whole way: the client's map, the wire with the option on, the edge session.
TEST(OmittedDescriptors, EdgeSessionFillsUploadedKeyFrameFromItsPoints) {
  test::SyntheticScene scene(150, 5);
  Map client(1);
  MutexLock client_lock(client.updateMutex());
  const test::SyntheticView v0 = scene.view(poseAt({0, 0, 0}), 0, true);
  const test::SyntheticView v1 = scene.view(poseAt({0.15, 0, 0}), 8, true);
  KeyFrame* k0 = scene.addKeyFrame(client, v0, 0, true);
  KeyFrame* k1 = scene.addKeyFrame(client, v1, 1, false);
  std::map<int, MapPoint*> point_of_scene;
  for (std::size_t i = 0; i < v0.scene_point.size(); ++i) {
    point_of_scene[v0.scene_point[i]] = k0->point(i);
  }
  std::vector<std::size_t> known;  // k1 keypoints naming k0's points
  std::vector<MapPoint*> k1_new_points;
  for (std::size_t j = 0; j < v1.scene_point.size(); ++j) {
    const auto it = point_of_scene.find(v1.scene_point[j]);
    // Every seventh keypoint gets a point of its own (as client triangulation would make).
    if (it != point_of_scene.end() && j % 7 != 0) {
      client.addObservation(it->second, k1, j);
      known.push_back(j);
    } else {
      MapPoint* p =
          client.createMapPoint(scene.points()[static_cast<std::size_t>(v1.scene_point[j])], k1);
      client.addObservation(p, k1, j);
      client.refreshPoint(p);
      k1_new_points.push_back(p);
    }
  }
  ASSERT_GE(known.size(), 30u);
  ASSERT_GE(k1_new_points.size(), 3u);

  WireEncodeOptions wire;
  wire.omit_known_point_descriptors = true;
  const auto throughTheWire = [&](const KeyFrameUpload& upload) {
    v1::KeyFrameUpload message;
    toProto(upload, &message, wire);
    return fromProto(message);
  };
  KeyFrameUpload first;
  first.sequence = 1;
  first.keyframe = keyFrameRecord(*k0);
  for (MapPoint* p : k0->goodPoints()) first.new_points.push_back(mapPointRecord(*p));
  KeyFrameUpload second;
  second.sequence = 2;
  second.keyframe = keyFrameRecord(*k1);
  for (MapPoint* p : k1_new_points) second.new_points.push_back(mapPointRecord(*p));
  EXPECT_EQ(wireSize(second, WireEncodeOptions{}) - wireSize(second, wire),
            32u * known.size() - 2u);

  EdgeMapSessionOptions options;
  options.backend.threaded = false;  // mapping runs inside onKeyFrame
  EdgeMapSession session(scene.camera(), Sensor::kRgbd, options, [](MapSlice) {});
  session.onKeyFrame(throughTheWire(first));

  // The edge erases one of the points before the client hears of it.
  const std::size_t vanished_keypoint = known[5];
  std::map<std::size_t, cv::Mat> point_descriptor;
  {
    MutexLock lock(session.map().updateMutex());
    MapPoint* vanished = session.map().mapPoint(k1->point(vanished_keypoint)->id());
    ASSERT_NE(vanished, nullptr);
    session.map().erasePoint(vanished);
    for (const std::size_t j : known) {
      if (j == vanished_keypoint) continue;
      const MapPoint* p = session.map().mapPoint(k1->point(j)->id());
      ASSERT_NE(p, nullptr) << j;
      point_descriptor[j] = p->descriptor().clone();
      // The keypoint was within the matching threshold of it, not equal (8 bits flipped).
      EXPECT_GT(hamming(p->descriptor(), k1->features().descriptor(j)), 0.0);
    }
  }
  const KeyFrameUpload decoded = throughTheWire(second);
  ASSERT_EQ(decoded.keyframe.features.descriptor_omitted.size(), k1->size());
  session.onKeyFrame(decoded);

  MutexLock lock(session.map().updateMutex());
  const KeyFrame* on_edge = session.map().keyFrame(k1->id());
  ASSERT_NE(on_edge, nullptr);
  for (const std::size_t j : known) {
    if (j == vanished_keypoint) continue;
    EXPECT_EQ(hamming(on_edge->features().descriptor(j), point_descriptor[j]), 0.0) << j;
  }
  for (MapPoint* p : k1_new_points) {  // new points' keypoints travel with their own
    const std::size_t j = p->observations().begin()->second.index;
    EXPECT_EQ(hamming(on_edge->features().descriptor(j), k1->features().descriptor(j)), 0.0);
  }
  // The vanished point's keypoint: no point, even after mapping searched for new ones, and a
  // descriptor far from every other.
  EXPECT_EQ(on_edge->point(vanished_keypoint), nullptr);
  const cv::Mat lost_row = on_edge->features().descriptor(vanished_keypoint);
  const KeyFrame* k0_on_edge = session.map().keyFrame(k0->id());
  for (std::size_t i = 0; i < k0_on_edge->size(); ++i) {
    EXPECT_GT(hamming(lost_row, k0_on_edge->features().descriptor(i)), 90.0) << i;
  }
  const EdgeMapSessionStats stats = session.stats();
  EXPECT_EQ(stats.descriptors_filled, known.size() - 1);
  EXPECT_EQ(stats.descriptors_lost, 1u);
}

}  // namespace
}  // namespace edgeslam
