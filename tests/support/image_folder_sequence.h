#pragma once
// Writes an image-folder dataset (frames, times.txt, camera.yaml of 7-Scenes' camera) from real
// frames a test has altered: repeated, reordered, blanked.
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <opencv2/imgcodecs.hpp>
#include <string>
#include <utility>
#include <vector>

#include "io/dataset.h"
#include "synth/degenerate_frames.h"

namespace edgeslam::test {

struct StampedImage {
  cv::Mat image;
  double timestamp = 0.0;
};

inline void writeImageFolder(const std::filesystem::path& folder,
                             const std::vector<StampedImage>& frames) {
  std::filesystem::create_directories(folder);
  std::ofstream(folder / "camera.yaml")
      << "width: 640\nheight: 480\nfx: 585\nfy: 585\ncx: 320\ncy: 240\nfps: 30\n";
  std::ofstream times(folder / "times.txt");
  times << std::setprecision(12);
  for (std::size_t i = 0; i < frames.size(); ++i) {
    char name[32];
    std::snprintf(name, sizeof(name), "frame_%04zu.png", i);
    cv::imwrite((folder / name).string(), frames[i].image);
    times << frames[i].timestamp << "\n";
  }
}

// Frames 0-139 of the 7-Scenes walk; 90-99 overexposed to white; frame 40 delivered twice with
// its timestamp (a duplicated frame) and frame 115 again after frame 120 (out of order).
inline std::vector<StampedImage> walkWithDisorder(DatasetReader& reader) {
  std::vector<StampedImage> frames;
  for (std::size_t i = 0; i < 140; ++i) {
    const cv::Mat gray = reader.load(i).gray;
    const double t = static_cast<double>(i) / 30.0;
    frames.push_back({i >= 90 && i < 100 ? overexposed(gray, 8.0) : gray, t});
    if (i == 40) frames.push_back(frames.back());
    if (i == 120) frames.push_back({reader.load(115).gray, 115.0 / 30.0});
  }
  return frames;
}

}  // namespace edgeslam::test
