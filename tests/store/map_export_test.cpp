// Exports of a stored map: TUM (a line per keyframe), PLY (a vertex per point), COLMAP text model
// (images whose 2-D points and points whose tracks agree).
#include "store/map_export.h"

#include <gtest/gtest.h>

#include <fstream>
#include <sstream>

#include "map/map_replication.h"
#include "store_fixture.h"

namespace edgeslam {
namespace {

std::vector<std::string> dataLines(const std::filesystem::path& file) {
  std::ifstream in(file);
  std::vector<std::string> lines;
  for (std::string line; std::getline(in, line);) {
    if (!line.empty() && line[0] != '#') lines.push_back(line);
  }
  return lines;
}

StoredMap storedSmallMap(const test::SmallMap& small) REQUIRES(small.map.updateMutex()) {
  StoredMap map;
  map.name = "small";
  StoredSession session;
  session.id = 1;
  session.info = small.info();
  for (const KeyFrame* kf : small.map.keyFrames()) session.keyframes.push_back(keyFrameRecord(*kf));
  for (const MapPoint* p : small.map.mapPoints()) session.points.push_back(mapPointRecord(*p));
  map.sessions.push_back(std::move(session));
  return map;
}

TEST(MapExport, TumPlyAndColmapDescribeTheSameMap) {
  const test::SmallMap small;
  MutexLock lock(small.map.updateMutex());
  const StoredMap map = storedSmallMap(small);
  const auto dir = test::freshStoreDir("export");
  std::filesystem::create_directories(dir);

  exportTum(map, dir / "keyframes.tum");
  const auto tum = dataLines(dir / "keyframes.tum");
  ASSERT_EQ(tum.size(), 3u);
  std::istringstream first(tum[1]);
  double t, x, y, z, qx, qy, qz, qw;
  first >> t >> x >> y >> z >> qx >> qy >> qz >> qw;
  const Eigen::Vector3d centre = small.keyframes[1]->cameraCenter();
  EXPECT_NEAR(x, centre.x(), 1e-6);
  EXPECT_NEAR(y, centre.y(), 1e-6);
  EXPECT_NEAR(z, centre.z(), 1e-6);
  EXPECT_NEAR(qx * qx + qy * qy + qz * qz + qw * qw, 1.0, 1e-6);

  exportPly(map, dir / "points.ply");
  const auto ply = dataLines(dir / "points.ply");
  const std::string vertex_line = "element vertex " + std::to_string(small.map.pointCount());
  EXPECT_NE(std::find(ply.begin(), ply.end(), vertex_line), ply.end());
  const auto header_end = std::find(ply.begin(), ply.end(), "end_header");
  ASSERT_NE(header_end, ply.end());
  EXPECT_EQ(static_cast<std::size_t>(ply.end() - header_end - 1), small.map.pointCount());

  exportColmap(map, dir / "colmap");
  const auto cameras = dataLines(dir / "colmap" / "cameras.txt");
  ASSERT_EQ(cameras.size(), 1u);
  EXPECT_EQ(cameras[0], "1 PINHOLE 640 480 500 500 320 240");
  const auto images = dataLines(dir / "colmap" / "images.txt");
  ASSERT_EQ(images.size(), 6u);  // two lines per image
  const auto points = dataLines(dir / "colmap" / "points3D.txt");
  ASSERT_EQ(points.size(), small.map.pointCount());
  // Every track entry names an image and a 2-D point of that image which names the point back.
  std::vector<std::vector<long long>> image_points(4);
  for (std::size_t i = 0; i < 3; ++i) {
    std::istringstream header(images[2 * i]);
    int image_id = 0;
    header >> image_id;
    std::istringstream row(images[2 * i + 1]);
    double u, v;
    long long id;
    while (row >> u >> v >> id) image_points[image_id].push_back(id);
    EXPECT_EQ(image_points[image_id].size(), small.keyframes[i]->features().keypoints.size());
  }
  std::size_t track_entries = 0;
  for (const std::string& line : points) {
    std::istringstream row(line);
    long long id;
    double px, py, pz, error;
    int r, g, b;
    row >> id >> px >> py >> pz >> r >> g >> b >> error;
    int image;
    std::size_t index;
    while (row >> image >> index) {
      ASSERT_LT(index, image_points[image].size());
      EXPECT_EQ(image_points[image][index], id);
      ++track_entries;
    }
  }
  EXPECT_GT(track_entries, small.map.pointCount());
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace edgeslam
