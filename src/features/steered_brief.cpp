#include "features/steered_brief.h"

#include <fmt/format.h>

#include <cmath>
#include <cstdint>
#include <numbers>
#include <stdexcept>

#include "features/descriptor_distance.h"

namespace edgeslam {
namespace {

class SplitMix64 {
 public:
  explicit SplitMix64(std::uint64_t seed) : state_(seed) {}
  std::uint64_t next() {
    std::uint64_t z = (state_ += 0x9E3779B97F4A7C15ULL);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
    return z ^ (z >> 31);
  }
  // Uniform in (0, 1]: never 0, so log() below is finite.
  double uniform() { return (static_cast<double>(next() >> 11) + 1.0) * 0x1.0p-53; }

 private:
  std::uint64_t state_;
};

std::array<BriefPair, 256> generatePattern() {
  constexpr double kPatchSize = 2 * kBriefPatternRadius + 1;
  constexpr double kSigma = kPatchSize / 5.0;
  constexpr double kMaxRadius2 = kBriefPatternRadius * kBriefPatternRadius;
  SplitMix64 rng(0x0EDCE51A3ULL);
  auto gaussianPoint = [&]() {
    while (true) {
      const double r = kSigma * std::sqrt(-2.0 * std::log(rng.uniform()));
      const double phi = 2.0 * std::numbers::pi * rng.uniform();
      const cv::Point2f p(static_cast<float>(std::round(r * std::cos(phi))),
                          static_cast<float>(std::round(r * std::sin(phi))));
      if (p.x * p.x + p.y * p.y <= kMaxRadius2) return p;
    }
  };
  std::array<BriefPair, 256> pattern{};
  for (BriefPair& pair : pattern) {
    cv::Point2f a, b;
    do {
      a = gaussianPoint();
      b = gaussianPoint();
    } while (a == b);
    pair = {a.x, a.y, b.x, b.y};
  }
  return pattern;
}

}  // namespace

const std::array<BriefPair, 256>& steeredBriefPattern() {
  static const std::array<BriefPair, 256> pattern = generatePattern();
  return pattern;
}

namespace {

// The pattern rotated to kAngleBins evenly spaced angles, as integer pixel offsets: steering a
// keypoint is then a table lookup instead of 512 rotations and roundings. With 128 bins the angle
// is off by at most 1.4 degrees, under 0.4 px at the pattern's rim (the image is blurred with
// sigma 2 before sampling).
constexpr int kAngleBins = 128;

struct RotatedPatterns {
  std::int8_t offsets[kAngleBins][256][4];  // dx1, dy1, dx2, dy2 per test
};

const RotatedPatterns& rotatedPatterns() {
  static const RotatedPatterns table = [] {
    RotatedPatterns t{};
    const auto& pattern = steeredBriefPattern();
    for (int bin = 0; bin < kAngleBins; ++bin) {
      const double angle = 2.0 * std::numbers::pi * bin / kAngleBins;
      const double c = std::cos(angle), s = std::sin(angle);
      auto turn = [&](float x, float y, std::int8_t* out) {
        out[0] = static_cast<std::int8_t>(std::lround(x * c - y * s));
        out[1] = static_cast<std::int8_t>(std::lround(x * s + y * c));
      };
      for (int i = 0; i < 256; ++i) {
        turn(pattern[i].x1, pattern[i].y1, &t.offsets[bin][i][0]);
        turn(pattern[i].x2, pattern[i].y2, &t.offsets[bin][i][2]);
      }
    }
    return t;
  }();
  return table;
}

int angleBin(float angle_deg) {
  const int bin = static_cast<int>(std::lround(angle_deg * (kAngleBins / 360.0)));
  return ((bin % kAngleBins) + kAngleBins) % kAngleBins;
}

}  // namespace

void computeSteeredBrief(const cv::Mat& smoothed, std::span<const cv::KeyPoint> keypoints,
                         cv::Mat& descriptors, int first_row) {
  if (smoothed.type() != CV_8UC1) {
    throw std::invalid_argument("steered BRIEF: the image must be CV_8UC1");
  }
  if (descriptors.type() != CV_8UC1 || descriptors.cols != kDescriptorBytes || first_row < 0 ||
      first_row + static_cast<int>(keypoints.size()) > descriptors.rows) {
    throw std::invalid_argument(
        fmt::format("steered BRIEF: descriptor matrix {}x{} cannot take {} rows from row {}",
                    descriptors.rows, descriptors.cols, keypoints.size(), first_row));
  }
  const RotatedPatterns& table = rotatedPatterns();
  const int step = static_cast<int>(smoothed.step1());
  constexpr int r = kBriefPatternRadius;
  for (std::size_t k = 0; k < keypoints.size(); ++k) {
    const cv::KeyPoint& kp = keypoints[k];
    const int cx = cvRound(kp.pt.x);
    const int cy = cvRound(kp.pt.y);
    if (cx < r || cy < r || cx >= smoothed.cols - r || cy >= smoothed.rows - r ||
        !std::isfinite(kp.angle)) {
      throw std::invalid_argument(
          fmt::format("steered BRIEF: keypoint ({}, {}) angle {} is closer than {} px to the "
                      "border of the {}x{} image or has no valid angle",
                      kp.pt.x, kp.pt.y, kp.angle, r, smoothed.cols, smoothed.rows));
    }
    const std::uint8_t* center = smoothed.ptr<std::uint8_t>(cy) + cx;
    const auto& tests = table.offsets[angleBin(kp.angle)];
    std::uint8_t* out = descriptors.ptr<std::uint8_t>(first_row + static_cast<int>(k));
    for (int byte = 0; byte < kDescriptorBytes; ++byte) {
      std::uint8_t bits = 0;
      for (int bit = 0; bit < 8; ++bit) {
        const std::int8_t* t = tests[8 * byte + bit];
        const int a = center[t[1] * step + t[0]];
        const int b = center[t[3] * step + t[2]];
        bits |= static_cast<std::uint8_t>((a < b) << bit);
      }
      out[byte] = bits;
    }
  }
}

}  // namespace edgeslam
