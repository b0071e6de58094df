#include "io/trajectory.h"

#include <fmt/format.h>

#include <cmath>
#include <fstream>
#include <sstream>
#include <string>

#include "io/dataset.h"

namespace edgeslam {
namespace {

std::ifstream openForReading(const std::filesystem::path& path) {
  std::ifstream in(path);
  if (!in) throw DatasetError(fmt::format("cannot open {}", path.string()));
  return in;
}

std::ofstream openForWriting(const std::filesystem::path& path) {
  if (path.has_parent_path()) std::filesystem::create_directories(path.parent_path());
  std::ofstream out(path);
  if (!out) throw DatasetError(fmt::format("cannot write {}", path.string()));
  return out;
}

bool isBlankOrComment(const std::string& line) {
  const auto first = line.find_first_not_of(" \t\r");
  return first == std::string::npos || line[first] == '#';
}

// Parses exactly `count` finite numbers (commas count as separators) or throws naming file:line.
std::vector<double> parseNumbers(const std::string& line, std::size_t count,
                                 const std::filesystem::path& path, int line_number) {
  std::string cleaned = line;
  for (char& c : cleaned) {
    if (c == ',') c = ' ';
  }
  std::istringstream stream(cleaned);
  std::vector<double> values;
  std::string token;
  while (stream >> token) {
    try {
      std::size_t used = 0;
      const double v = std::stod(token, &used);
      if (used != token.size() || !std::isfinite(v)) throw std::invalid_argument(token);
      values.push_back(v);
    } catch (const std::exception&) {
      throw DatasetError(
          fmt::format("{}:{}: '{}' is not a number", path.string(), line_number, token));
    }
  }
  if (values.size() != count) {
    throw DatasetError(fmt::format("{}:{}: expected {} numbers, found {}", path.string(),
                                   line_number, count, values.size()));
  }
  return values;
}

}  // namespace

Trajectory readTumTrajectory(const std::filesystem::path& path) {
  std::ifstream in = openForReading(path);
  Trajectory trajectory;
  std::string line;
  int line_number = 0;
  while (std::getline(in, line)) {
    ++line_number;
    if (isBlankOrComment(line)) continue;
    const auto v = parseNumbers(line, 8, path, line_number);
    const Eigen::Quaterniond q(v[7], v[4], v[5], v[6]);
    if (q.norm() < 1e-6) {
      throw DatasetError(fmt::format("{}:{}: zero quaternion", path.string(), line_number));
    }
    trajectory.push_back({v[0], SE3d(q, Eigen::Vector3d(v[1], v[2], v[3]))});
  }
  return trajectory;
}

void writeTumTrajectory(const std::filesystem::path& path, const Trajectory& trajectory) {
  std::ofstream out = openForWriting(path);
  for (const auto& [timestamp, pose] : trajectory) {
    const Eigen::Vector3d& t = pose.translation();
    const Eigen::Quaterniond& q = pose.rotation();
    out << fmt::format("{:.6f} {:.9f} {:.9f} {:.9f} {:.9f} {:.9f} {:.9f} {:.9f}\n", timestamp,
                       t.x(), t.y(), t.z(), q.x(), q.y(), q.z(), q.w());
  }
  if (!out) throw DatasetError(fmt::format("failed writing {}", path.string()));
}

std::vector<SE3d> readKittiPoses(const std::filesystem::path& path) {
  std::ifstream in = openForReading(path);
  std::vector<SE3d> poses;
  std::string line;
  int line_number = 0;
  while (std::getline(in, line)) {
    ++line_number;
    if (isBlankOrComment(line)) continue;
    const auto v = parseNumbers(line, 12, path, line_number);
    Eigen::Matrix<double, 3, 4> m;
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 4; ++c) m(r, c) = v[static_cast<std::size_t>(r * 4 + c)];
    }
    poses.push_back(SE3d::fromMatrix3x4(m));
  }
  return poses;
}

void writeKittiPoses(const std::filesystem::path& path, const std::vector<SE3d>& poses) {
  std::ofstream out = openForWriting(path);
  for (const SE3d& pose : poses) {
    const auto m = pose.matrix3x4();
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 4; ++c) {
        out << fmt::format("{:.9e}", m(r, c)) << ((r == 2 && c == 3) ? '\n' : ' ');
      }
    }
  }
  if (!out) throw DatasetError(fmt::format("failed writing {}", path.string()));
}

std::vector<double> readTimes(const std::filesystem::path& path) {
  std::ifstream in = openForReading(path);
  std::vector<double> times;
  std::string line;
  int line_number = 0;
  while (std::getline(in, line)) {
    ++line_number;
    if (isBlankOrComment(line)) continue;
    times.push_back(parseNumbers(line, 1, path, line_number)[0]);
  }
  return times;
}

Trajectory kittiToTrajectory(const std::vector<SE3d>& poses, const std::vector<double>& times) {
  if (!times.empty() && times.size() != poses.size()) {
    throw DatasetError(fmt::format("{} poses but {} timestamps", poses.size(), times.size()));
  }
  Trajectory trajectory;
  trajectory.reserve(poses.size());
  for (std::size_t i = 0; i < poses.size(); ++i) {
    trajectory.push_back({times.empty() ? static_cast<double>(i) : times[i], poses[i]});
  }
  return trajectory;
}

}  // namespace edgeslam
