// Microsoft 7-Scenes: frame-NNNNNN.color.{png,jpg}, .depth.png (uint16 mm, 65535 = invalid),
// .pose.txt (4x4 camera-to-world), camera-intrinsics.txt (3x3 K; the published values when
// absent). No timestamps: frame number / 30 s.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "io/reader_support.h"
#include "io/readers.h"

namespace edgeslam::detail {
namespace {

constexpr double kFps = 30.0;
constexpr double kDepthFactor = 1000.0;  // millimetres
constexpr std::uint16_t kInvalidDepth = std::numeric_limits<std::uint16_t>::max();

struct SceneFrame {
  long number;
  std::filesystem::path color;
};

std::vector<SceneFrame> findFrames(const std::filesystem::path& folder) {
  std::vector<SceneFrame> frames;
  for (const auto& entry : std::filesystem::directory_iterator(folder)) {
    if (const auto number = sevenScenesFrameNumber(entry.path().filename().string())) {
      frames.push_back({*number, entry.path()});
    }
  }
  std::sort(frames.begin(), frames.end(),
            [](const auto& a, const auto& b) { return a.number < b.number; });
  return frames;
}

std::filesystem::path sibling(const std::filesystem::path& color, const char* suffix) {
  std::string name = color.filename().string();
  name = name.substr(0, name.find(".color.")) + suffix;
  return color.parent_path() / name;
}

// Reads a 4x4 camera-to-world matrix. Non-finite entries (how 7-Scenes marks untracked frames)
// give no pose; malformed text is an error.
std::optional<SE3d> readPoseMatrix(const std::filesystem::path& path) {
  const auto rows = readTable(path, 4);
  std::vector<double> values;
  for (const TableRow& row : rows) {
    for (const std::string& token : row.fields) {
      std::size_t used = 0;
      double value = 0.0;
      try {
        value = std::stod(token, &used);
      } catch (const std::out_of_range&) {
        value = std::numeric_limits<double>::infinity();
        used = token.size();
      } catch (const std::exception&) {
      }
      if (used != token.size() || used == 0) {
        throw DatasetError(
            fmt::format("{}:{}: '{}' is not a number", path.string(), row.line, token));
      }
      values.push_back(value);
    }
  }
  if (values.size() != 16) {
    throw DatasetError(fmt::format("{}: expected a 4x4 matrix (16 numbers), found {}",
                                   path.string(), values.size()));
  }
  if (!std::all_of(values.begin(), values.end(), [](double v) { return std::isfinite(v); })) {
    return std::nullopt;
  }
  Eigen::Matrix4d m;
  for (int r = 0; r < 4; ++r) {
    for (int c = 0; c < 4; ++c) m(r, c) = values[static_cast<std::size_t>(r * 4 + c)];
  }
  const double rotation_error =
      (m.topLeftCorner<3, 3>() * m.topLeftCorner<3, 3>().transpose() - Eigen::Matrix3d::Identity())
          .norm();
  if (rotation_error > 1e-3 || (m.row(3) - Eigen::RowVector4d(0, 0, 0, 1)).norm() > 1e-6) {
    throw DatasetError(fmt::format("{}: not a rigid transform", path.string()));
  }
  return SE3d::fromMatrix(m);
}

CameraIntrinsics readIntrinsics(const std::filesystem::path& folder) {
  CameraIntrinsics in;
  in.width = 640;
  in.height = 480;
  in.depth_factor = kDepthFactor;
  in.fps = kFps;
  const auto path = folder / "camera-intrinsics.txt";
  if (!std::filesystem::exists(path)) {
    in.fx = in.fy = 585.0, in.cx = 320.0, in.cy = 240.0;  // the dataset's published values
    return in;
  }
  const auto rows = readTable(path, 3);
  if (rows.size() != 3) {
    throw DatasetError(fmt::format("{}: expected 3 rows of a 3x3 matrix", path.string()));
  }
  double k[3][3];
  for (int r = 0; r < 3; ++r) {
    const TableRow& row = rows[static_cast<std::size_t>(r)];
    if (row.fields.size() != 3) {
      throw DatasetError(fmt::format("{}:{}: expected 3 numbers, found {}", path.string(), row.line,
                                     row.fields.size()));
    }
    for (int c = 0; c < 3; ++c) {
      k[r][c] = parseNumber(row.fields[static_cast<std::size_t>(c)], path, row.line);
    }
  }
  in.fx = k[0][0], in.fy = k[1][1], in.cx = k[0][2], in.cy = k[1][2];
  return in;
}

class SevenScenesReader : public TabulatedReader {
 public:
  SevenScenesReader(const std::filesystem::path& folder, const DatasetOptions& options) {
    info_.format = DatasetFormat::kSevenScenes;
    info_.path = folder;
    info_.fps = kFps;
    const auto frames = findFrames(folder);
    if (frames.empty()) {
      throw DatasetError(fmt::format("{}: no frame-NNNNNN.color.png|jpg files", folder.string()));
    }
    info_.has_depth = std::filesystem::exists(sibling(frames.front().color, ".depth.png"));
    for (const SceneFrame& frame : frames) {
      color_files_.push_back(frame.color);
      timestamps_.push_back(static_cast<double>(frame.number) / kFps);
      const auto pose_file = sibling(frame.color, ".pose.txt");
      ground_truth_.push_back(std::filesystem::exists(pose_file) ? readPoseMatrix(pose_file)
                                                                 : std::nullopt);
    }
    const cv::Mat first = readImage(color_files_.front());
    camera_ = resolveCamera(readIntrinsics(folder), options, first.size(), color_files_.front(),
                            std::string());
    finishTables();
  }

  DatasetFrame load(std::size_t index) override {
    DatasetFrame frame = beginFrame(index, std::string());
    const std::filesystem::path& color = color_files_[index];
    frame.name = color.filename().string();
    readFrameImage(color, content_.color, frame);
    checkImageSize(frame.gray, imageSize(camera_), color, "image");
    if (info_.has_depth && content_.depth) {
      const auto depth = sibling(color, ".depth.png");
      frame.depth =
          depthToMetres(readImage(depth), camera_.intrinsics().depth_factor, depth, kInvalidDepth);
      checkImageSize(frame.depth, imageSize(camera_), depth, "depth image");
    }
    return frame;
  }

 private:
  std::vector<std::filesystem::path> color_files_;
};

}  // namespace

std::unique_ptr<DatasetReader> openSevenScenesDataset(const std::filesystem::path& folder,
                                                      const DatasetOptions& options) {
  return std::make_unique<SevenScenesReader>(folder, options);
}

}  // namespace edgeslam::detail
