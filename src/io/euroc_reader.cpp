// EuRoC MAV (ASL folder layout): mav0/cam0/{data.csv,sensor.yaml,data/}, optional mav0/cam1 (raw,
// unrectified right camera), ground truth mav0/state_groundtruth_estimate0/data.csv (body poses,
// nanosecond stamps). Camera pose = T_WB(t) * T_BS(cam0), T_WB interpolated at the frame's time.
// Right images are paired by identical timestamps; a frame without one has an empty right_gray.
#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include <charconv>
#include <fstream>
#include <sstream>
#include <unordered_map>

#include "io/pose_interpolation.h"
#include "io/reader_support.h"
#include "io/readers.h"

namespace edgeslam::detail {
namespace {

std::int64_t parseNanoseconds(const std::string& token, const std::filesystem::path& path,
                              int line) {
  std::int64_t value = 0;
  const auto [end, error] = std::from_chars(token.data(), token.data() + token.size(), value);
  if (error != std::errc() || end != token.data() + token.size()) {
    throw DatasetError(
        fmt::format("{}:{}: '{}' is not a nanosecond timestamp", path.string(), line, token));
  }
  return value;
}

double toSeconds(std::int64_t nanoseconds) {
  return static_cast<double>(nanoseconds) * 1e-9;
}

// EuRoC's sensor.yaml starts with OpenCV's "%YAML:1.0" directive, which is not valid YAML 1.2:
// drop directive lines and parse the rest.
YAML::Node loadSensorYaml(const std::filesystem::path& path) {
  std::ifstream in(path);
  if (!in) throw DatasetError(fmt::format("cannot open {}", path.string()));
  std::ostringstream text;
  std::string line;
  while (std::getline(in, line)) {
    text << (line.starts_with('%') ? "" : line) << '\n';  // keep line numbers
  }
  try {
    YAML::Node root = YAML::Load(text.str());
    if (!root.IsMap()) throw DatasetError(fmt::format("{}: expected a mapping", path.string()));
    return root;
  } catch (const YAML::Exception& e) {
    throw DatasetError(
        fmt::format("{}:{}: not valid YAML: {}", path.string(), e.mark.line + 1, e.msg));
  }
}

std::vector<double> numbers(const YAML::Node& root, const char* key, std::size_t min_count,
                            std::size_t max_count, const std::filesystem::path& path) {
  const YAML::Node node = root[key];
  if (!node) throw DatasetError(fmt::format("{}: missing '{}'", path.string(), key));
  const YAML::Node list = node.IsMap() ? node["data"] : node;
  std::vector<double> values;
  try {
    if (list && list.IsScalar()) {
      values.push_back(list.as<double>());
    } else if (list && list.IsSequence()) {
      for (const auto& item : list) values.push_back(item.as<double>());
    } else {
      throw YAML::Exception(node.Mark(), "not a list");
    }
  } catch (const YAML::Exception&) {
    throw DatasetError(fmt::format("{}:{}: '{}' must be a list of numbers", path.string(),
                                   node.Mark().line + 1, key));
  }
  if (values.size() < min_count || values.size() > max_count) {
    throw DatasetError(fmt::format("{}:{}: '{}' has {} numbers, expected {}", path.string(),
                                   node.Mark().line + 1, key, values.size(),
                                   min_count == max_count
                                       ? fmt::format("{}", min_count)
                                       : fmt::format("{} to {}", min_count, max_count)));
  }
  return values;
}

struct EurocCamera {
  CameraIntrinsics intrinsics;
  SE3d body_from_sensor;
};

EurocCamera readSensor(const std::filesystem::path& path) {
  const YAML::Node root = loadSensorYaml(path);
  for (const char* key : {"camera_model", "distortion_model"}) {
    if (!root[key]) continue;
    const std::string value = root[key].as<std::string>();
    if (value != "pinhole" && value != "radial-tangential" && value != "radtan") {
      throw DatasetError(fmt::format("{}:{}: unsupported {} '{}' (pinhole, radial-tangential only)",
                                     path.string(), root[key].Mark().line + 1, key, value));
    }
  }
  EurocCamera camera;
  CameraIntrinsics& in = camera.intrinsics;
  const auto k = numbers(root, "intrinsics", 4, 4, path);
  in.fx = k[0], in.fy = k[1], in.cx = k[2], in.cy = k[3];
  const auto resolution = numbers(root, "resolution", 2, 2, path);
  in.width = static_cast<int>(resolution[0]);
  in.height = static_cast<int>(resolution[1]);
  const auto d = numbers(root, "distortion_coefficients", 4, 5, path);
  in.distortion = {d[0], d[1], d[2], d[3], d.size() > 4 ? d[4] : 0.0};
  if (root["rate_hz"]) in.fps = numbers(root, "rate_hz", 1, 1, path)[0];
  const auto t = numbers(root, "T_BS", 16, 16, path);
  Eigen::Matrix4d m;
  for (int r = 0; r < 4; ++r) {
    for (int c = 0; c < 4; ++c) m(r, c) = t[static_cast<std::size_t>(r * 4 + c)];
  }
  camera.body_from_sensor = SE3d::fromMatrix(m);
  return camera;
}

struct CameraStream {
  std::vector<std::int64_t> stamps;
  std::vector<std::filesystem::path> files;
};

CameraStream readStream(const std::filesystem::path& camera_folder) {
  const auto list = camera_folder / "data.csv";
  CameraStream stream;
  for (const TableRow& row : readTable(list, 2)) {
    stream.stamps.push_back(parseNanoseconds(row.fields[0], list, row.line));
    stream.files.push_back(camera_folder / "data" / row.fields[1]);
    if (stream.stamps.size() > 1 &&
        stream.stamps.back() <= stream.stamps[stream.stamps.size() - 2]) {
      throw DatasetError(fmt::format("{}:{}: timestamps must increase", list.string(), row.line));
    }
  }
  return stream;
}

Trajectory readBodyGroundTruth(const std::filesystem::path& path) {
  Trajectory trajectory;
  for (const TableRow& row : readTable(path, 8)) {
    double v[7];
    for (int i = 0; i < 7; ++i) {
      v[i] = parseNumber(row.fields[static_cast<std::size_t>(i + 1)], path, row.line);
    }
    const Eigen::Quaterniond q(v[3], v[4], v[5], v[6]);  // w x y z
    if (q.norm() < 1e-6) {
      throw DatasetError(fmt::format("{}:{}: zero quaternion", path.string(), row.line));
    }
    trajectory.push_back({toSeconds(parseNanoseconds(row.fields[0], path, row.line)),
                          SE3d(q, Eigen::Vector3d(v[0], v[1], v[2]))});
  }
  sortByTime(trajectory);
  return trajectory;
}

std::filesystem::path eurocRoot(const std::filesystem::path& path) {
  if (std::filesystem::is_directory(path / "mav0")) return path / "mav0";
  return path;  // the mav0 folder itself
}

class EurocReader : public TabulatedReader {
 public:
  EurocReader(const std::filesystem::path& folder, const DatasetOptions& options) {
    info_.format = DatasetFormat::kEuroc;
    info_.path = folder;
    const auto root = eurocRoot(folder);
    if (!std::filesystem::exists(root / "cam0" / "data.csv")) {
      throw DatasetError(
          fmt::format("{}: EuRoC folder without mav0/cam0/data.csv", folder.string()));
    }
    left_ = readStream(root / "cam0");
    if (left_.stamps.empty()) {
      throw DatasetError(fmt::format("{}: no frames", (root / "cam0" / "data.csv").string()));
    }
    std::vector<double> relative;  // exact intervals: epoch seconds in a double lose ~0.2 us
    for (std::int64_t stamp : left_.stamps) {
      timestamps_.push_back(toSeconds(stamp));
      relative.push_back(toSeconds(stamp - left_.stamps.front()));
    }
    info_.fps = fpsFromTimestamps(relative);

    std::optional<EurocCamera> left_camera;
    if (std::filesystem::exists(root / "cam0" / "sensor.yaml")) {
      left_camera = readSensor(root / "cam0" / "sensor.yaml");
    }
    std::optional<CameraIntrinsics> native;
    if (left_camera) native = left_camera->intrinsics;

    if (std::filesystem::exists(root / "cam1" / "data.csv")) {
      const CameraStream right = readStream(root / "cam1");
      std::unordered_map<std::int64_t, std::size_t> by_stamp;
      for (std::size_t i = 0; i < right.stamps.size(); ++i) by_stamp[right.stamps[i]] = i;
      for (std::int64_t stamp : left_.stamps) {
        const auto it = by_stamp.find(stamp);
        right_files_.push_back(it == by_stamp.end() ? std::filesystem::path()
                                                    : right.files[it->second]);
      }
      info_.has_stereo = true;
      if (native && std::filesystem::exists(root / "cam1" / "sensor.yaml")) {
        const EurocCamera right_camera = readSensor(root / "cam1" / "sensor.yaml");
        const SE3d left_from_right =
            left_camera->body_from_sensor.inverse() * right_camera.body_from_sensor;
        native->baseline_m = left_from_right.translation().norm();
      }
    }

    const auto ground_truth_file = root / "state_groundtruth_estimate0" / "data.csv";
    if (std::filesystem::exists(ground_truth_file)) {
      const Trajectory body = readBodyGroundTruth(ground_truth_file);
      // Without cam0/sensor.yaml (camera from --camera) T_BS is unknown: body poses are used.
      const SE3d body_from_camera = left_camera ? left_camera->body_from_sensor : SE3d();
      for (double t : timestamps_) {
        const auto world_from_body = interpolatePose(body, t, kDefaultPoseTimeTolerance);
        ground_truth_.push_back(world_from_body
                                    ? std::optional<SE3d>(*world_from_body * body_from_camera)
                                    : std::nullopt);
      }
    }

    const cv::Mat first = readImage(left_.files.front());
    camera_ = resolveCamera(
        native, options, first.size(), left_.files.front(),
        fmt::format("{}: no cam0/sensor.yaml; pass --camera FILE.yaml", root.string()));
    finishTables();
  }

  DatasetFrame load(std::size_t index) override {
    DatasetFrame frame = beginFrame(index, std::string());
    const std::filesystem::path& left = left_.files[index];
    frame.name = left.filename().string();
    readFrameImage(left, content_.color, frame);
    checkImageSize(frame.gray, imageSize(camera_), left, "image");
    if (!right_files_.empty() && !right_files_[index].empty() && content_.right) {
      DatasetFrame right;
      setImages(readImage(right_files_[index]), right_files_[index], right);
      checkImageSize(right.gray, imageSize(camera_), right_files_[index], "right image");
      frame.right_gray = right.gray;
    }
    return frame;
  }

 private:
  CameraStream left_;
  std::vector<std::filesystem::path> right_files_;
};

}  // namespace

std::unique_ptr<DatasetReader> openEurocDataset(const std::filesystem::path& folder,
                                                const DatasetOptions& options) {
  return std::make_unique<EurocReader>(folder, options);
}

}  // namespace edgeslam::detail
