#include "store/map_export.h"

#include <fmt/format.h>
#include <fmt/os.h>

#include <algorithm>
#include <unordered_map>

#include "store/store_error.h"

namespace edgeslam {
namespace {

// fmt's file output, with the failure named after the file.
fmt::ostream openOutput(const std::filesystem::path& file) {
  try {
    return fmt::output_file(file.string());
  } catch (const std::system_error& e) {
    throw StoreError(file.string() + ": cannot write: " + e.code().message());
  }
}

struct ColmapIds {
  std::unordered_map<KeyFrameId, std::uint32_t> images;
  std::unordered_map<MapPointId, std::uint64_t> points;
};

}  // namespace

void exportTum(const StoredMap& map, const std::filesystem::path& file) {
  std::vector<const KeyFrameRecord*> keyframes;
  for (const StoredSession& s : map.sessions) {
    for (const KeyFrameRecord& k : s.keyframes) keyframes.push_back(&k);
  }
  std::stable_sort(keyframes.begin(), keyframes.end(),
                   [](const auto* a, const auto* b) { return a->timestamp < b->timestamp; });
  auto out = openOutput(file);
  for (const KeyFrameRecord* k : keyframes) {
    const SE3d T_wc = k->T_cw.inverse();
    const Eigen::Vector3d& t = T_wc.translation();
    const Eigen::Quaterniond& q = T_wc.rotation();
    out.print("{:.6f} {:.9f} {:.9f} {:.9f} {:.9f} {:.9f} {:.9f} {:.9f}\n", k->timestamp, t.x(),
              t.y(), t.z(), q.x(), q.y(), q.z(), q.w());
  }
}

void exportPly(const StoredMap& map, const std::filesystem::path& file) {
  std::size_t count = 0;
  double low = 0.0, high = 0.0;
  for (const StoredSession& s : map.sessions) {
    for (const MapPointRecord& p : s.points) {
      low = count == 0 ? p.position.y() : std::min(low, p.position.y());
      high = count == 0 ? p.position.y() : std::max(high, p.position.y());
      ++count;
    }
  }
  auto out = openOutput(file);
  out.print(
      "ply\nformat ascii 1.0\ncomment edgeslam map '{}'\nelement vertex {}\nproperty float x\n"
      "property float y\nproperty float z\nproperty uchar red\nproperty uchar green\n"
      "property uchar blue\nend_header\n",
      map.name, count);
  const double span = std::max(high - low, 1e-9);
  for (const StoredSession& s : map.sessions) {
    for (const MapPointRecord& p : s.points) {
      // Cameras look along +z with y down: colour runs blue (top) to red (bottom).
      const double f = std::clamp((p.position.y() - low) / span, 0.0, 1.0);
      const int red = static_cast<int>(255 * f);
      const int green = static_cast<int>(255 * (1.0 - std::abs(2.0 * f - 1.0)));
      const int blue = 255 - red;
      out.print("{:.6f} {:.6f} {:.6f} {} {} {}\n", p.position.x(), p.position.y(), p.position.z(),
                red, green, blue);
    }
  }
}

void exportColmap(const StoredMap& map, const std::filesystem::path& folder) {
  std::error_code error;
  std::filesystem::create_directories(folder, error);
  if (error) throw StoreError(folder.string() + ": cannot create: " + error.message());
  auto cameras = openOutput(folder / "cameras.txt");
  auto images = openOutput(folder / "images.txt");
  auto points = openOutput(folder / "points3D.txt");
  cameras.print(
      "# Camera list with one line of data per camera:\n"
      "#   CAMERA_ID, MODEL, WIDTH, HEIGHT, PARAMS[]\n");
  images.print(
      "# Image list with two lines of data per image:\n"
      "#   IMAGE_ID, QW, QX, QY, QZ, TX, TY, TZ, CAMERA_ID, NAME\n"
      "#   POINTS2D[] as (X, Y, POINT3D_ID)\n");
  points.print(
      "# 3D point list with one line of data per point:\n"
      "#   POINT3D_ID, X, Y, Z, R, G, B, ERROR, TRACK[] as (IMAGE_ID, POINT2D_IDX)\n");
  std::uint32_t next_image = 1;
  std::uint64_t next_point = 1;
  for (std::size_t c = 0; c < map.sessions.size(); ++c) {
    const StoredSession& s = map.sessions[c];
    const int camera_id = static_cast<int>(c + 1);
    const PinholeCamera& camera = s.info.camera;
    cameras.print("{} PINHOLE {} {} {:.9g} {:.9g} {:.9g} {:.9g}\n", camera_id, camera.width(),
                  camera.height(), camera.fx(), camera.fy(), camera.cx(), camera.cy());
    ColmapIds ids;
    for (const KeyFrameRecord& k : s.keyframes) ids.images[k.id] = next_image++;
    for (const MapPointRecord& p : s.points) ids.points[p.id] = next_point++;
    for (const KeyFrameRecord& k : s.keyframes) {
      const Eigen::Quaterniond& q = k.T_cw.rotation();
      const Eigen::Vector3d& t = k.T_cw.translation();
      images.print("{} {:.12g} {:.12g} {:.12g} {:.12g} {:.12g} {:.12g} {:.12g} {} s{}_{:06d}.png\n",
                   ids.images[k.id], q.w(), q.x(), q.y(), q.z(), t.x(), t.y(), t.z(), camera_id,
                   s.id, k.frame_index);
      std::string line;
      for (std::size_t i = 0; i < k.features.keypoints.size(); ++i) {
        const cv::Point2f& pt = k.features.keypoints[i].pt;
        const auto point =
            i < k.point_ids.size() ? ids.points.find(k.point_ids[i]) : ids.points.end();
        const long long point_id =
            point != ids.points.end() ? static_cast<long long>(point->second) : -1;
        fmt::format_to(std::back_inserter(line), "{}{:.3f} {:.3f} {}", i == 0 ? "" : " ", pt.x,
                       pt.y, point_id);
      }
      images.print("{}\n", line);
    }
    for (const MapPointRecord& p : s.points) {
      std::string track;
      for (const PointObservationRecord& o : p.observations) {
        const auto image = ids.images.find(o.keyframe);
        if (image == ids.images.end()) continue;
        fmt::format_to(std::back_inserter(track), " {} {}", image->second, o.keypoint_index);
      }
      points.print("{} {:.9g} {:.9g} {:.9g} 128 128 128 0{}\n", ids.points[p.id], p.position.x(),
                   p.position.y(), p.position.z(), track);
    }
  }
}

}  // namespace edgeslam
