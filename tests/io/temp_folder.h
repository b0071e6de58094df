#pragma once
// A temporary folder removed at the end of the test, and small writers for synthetic datasets.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <random>
#include <string>

namespace edgeslam::test {

class TempFolder {
 public:
  TempFolder() {
    std::random_device seed;
    const auto name = "edgeslam-io-test-" + std::to_string(seed()) + std::to_string(seed());
    path_ = std::filesystem::temp_directory_path() / name;
    std::filesystem::create_directories(path_);
  }
  ~TempFolder() {
    std::error_code ignored;
    std::filesystem::remove_all(path_, ignored);
  }
  TempFolder(const TempFolder&) = delete;
  TempFolder& operator=(const TempFolder&) = delete;

  const std::filesystem::path& path() const { return path_; }
  std::filesystem::path operator/(const std::string& relative) const { return path_ / relative; }

 private:
  std::filesystem::path path_;
};

// A folder of this test process's own, removed when it exits: ctest runs each test in its own
// process, several at once.
inline std::filesystem::path processTempFolder(const std::string& name) {
  static const TempFolder scratch;
  return scratch / name;
}

inline void writeText(const std::filesystem::path& path, const std::string& text) {
  std::filesystem::create_directories(path.parent_path());
  std::ofstream out(path);
  out << text;
  ASSERT_TRUE(out.good()) << path;
}

// A textured image whose pixel (0,0) encodes `tag`, so tests can tell frames apart.
inline cv::Mat taggedImage(int width, int height, int type, int tag) {
  cv::Mat image(height, width, type);
  cv::randu(image, 0, 255);
  image.at<unsigned char>(0, 0) = static_cast<unsigned char>(tag);
  return image;
}

inline void writeImage(const std::filesystem::path& path, const cv::Mat& image) {
  std::filesystem::create_directories(path.parent_path());
  ASSERT_TRUE(cv::imwrite(path.string(), image)) << path;
}

inline std::string minimalCameraYaml(int width, int height, const std::string& extra = "") {
  return "width: " + std::to_string(width) + "\nheight: " + std::to_string(height) +
         "\nfx: 100\nfy: 101\ncx: " + std::to_string(width / 2) +
         "\ncy: " + std::to_string(height / 2) + "\n" + extra;
}

}  // namespace edgeslam::test
