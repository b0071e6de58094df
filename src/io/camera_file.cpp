#include "io/camera_file.h"

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include <array>
#include <cmath>
#include <fstream>
#include <set>
#include <string>
#include <string_view>

#include "io/dataset_error.h"

namespace edgeslam {
namespace {

constexpr std::array<std::string_view, 6> kRequiredKeys = {"width", "height", "fx",
                                                           "fy",    "cx",     "cy"};
constexpr std::array<std::string_view, 8> kOptionalKeys = {
    "k1", "k2", "p1", "p2", "k3", "depth_factor", "baseline_m", "fps"};

bool isKnownKey(const std::string& key) {
  for (auto known : kRequiredKeys) {
    if (key == known) return true;
  }
  for (auto known : kOptionalKeys) {
    if (key == known) return true;
  }
  return false;
}

std::string where(const std::filesystem::path& path, const YAML::Node& node) {
  const YAML::Mark mark = node.Mark();
  if (mark.line < 0) return path.string();
  return fmt::format("{}:{}", path.string(), mark.line + 1);
}

double readNumber(const std::filesystem::path& path, const std::string& key,
                  const YAML::Node& value) {
  if (!value.IsScalar()) {
    throw DatasetError(fmt::format("{}: '{}' must be a number", where(path, value), key));
  }
  double number = 0.0;
  try {
    number = value.as<double>();
  } catch (const YAML::Exception&) {
    throw DatasetError(fmt::format("{}: '{}' must be a number, got '{}'", where(path, value), key,
                                   value.Scalar()));
  }
  if (!std::isfinite(number)) {
    throw DatasetError(
        fmt::format("{}: '{}' must be finite, got '{}'", where(path, value), key, value.Scalar()));
  }
  return number;
}

int readPositiveInteger(const std::filesystem::path& path, const std::string& key,
                        const YAML::Node& value) {
  const double number = readNumber(path, key, value);
  if (number != std::floor(number) || number <= 0.0 || number > 1e6) {
    throw DatasetError(fmt::format("{}: '{}' must be a positive whole number, got '{}'",
                                   where(path, value), key, value.Scalar()));
  }
  return static_cast<int>(number);
}

}  // namespace

CameraIntrinsics loadCameraFile(const std::filesystem::path& path) {
  if (!std::filesystem::is_regular_file(path)) {
    throw DatasetError(fmt::format("camera file not found: {}", path.string()));
  }
  YAML::Node root;
  try {
    root = YAML::LoadFile(path.string());
  } catch (const YAML::Exception& e) {
    throw DatasetError(
        fmt::format("{}:{}: not valid YAML: {}", path.string(), e.mark.line + 1, e.msg));
  }
  if (!root.IsMap()) {
    throw DatasetError(fmt::format(
        "{}: a camera file must be a mapping of keys (width, height, fx, fy, cx, cy, ...)",
        path.string()));
  }

  std::set<std::string> seen;
  for (const auto& entry : root) {
    const std::string key = entry.first.as<std::string>();
    if (!isKnownKey(key)) {
      throw DatasetError(fmt::format(
          "{}: unknown key '{}' (allowed: width height fx fy cx cy k1 k2 p1 p2 k3 depth_factor "
          "baseline_m fps)",
          where(path, entry.first), key));
    }
    seen.insert(key);
  }
  for (auto key : kRequiredKeys) {
    if (!seen.contains(std::string(key))) {
      throw DatasetError(fmt::format("{}: missing required key '{}'", path.string(), key));
    }
  }

  const auto number = [&](const char* key, double fallback = 0.0) {
    return seen.contains(key) ? readNumber(path, key, root[key]) : fallback;
  };
  CameraIntrinsics in;
  in.width = readPositiveInteger(path, "width", root["width"]);
  in.height = readPositiveInteger(path, "height", root["height"]);
  in.fx = number("fx");
  in.fy = number("fy");
  in.cx = number("cx");
  in.cy = number("cy");
  in.distortion = {number("k1"), number("k2"), number("p1"), number("p2"), number("k3")};
  in.depth_factor = number("depth_factor");
  in.baseline_m = number("baseline_m");
  in.fps = number("fps");
  try {
    PinholeCamera check(in);
  } catch (const std::invalid_argument& e) {
    throw DatasetError(fmt::format("{}: {}", path.string(), e.what()));
  }
  return in;
}

void saveCameraFile(const std::filesystem::path& path, const CameraIntrinsics& in) {
  std::string text = "# edgeslam camera file (pinhole, radial-tangential distortion)\n";
  text += fmt::format("width: {}\nheight: {}\n", in.width, in.height);
  // fmt's default double format is the shortest text that reads back to the same value.
  text += fmt::format("fx: {}\nfy: {}\ncx: {}\ncy: {}\n", in.fx, in.fy, in.cx, in.cy);
  const auto optional = [&](const char* key, double value) {
    if (value != 0.0) text += fmt::format("{}: {}\n", key, value);
  };
  const Distortion& d = in.distortion;
  optional("k1", d.k1);
  optional("k2", d.k2);
  optional("p1", d.p1);
  optional("p2", d.p2);
  optional("k3", d.k3);
  optional("depth_factor", in.depth_factor);
  optional("baseline_m", in.baseline_m);
  optional("fps", in.fps);

  if (path.has_parent_path()) std::filesystem::create_directories(path.parent_path());
  std::ofstream out(path);
  out << text;
  if (!out) throw DatasetError(fmt::format("cannot write camera file {}", path.string()));
}

}  // namespace edgeslam
