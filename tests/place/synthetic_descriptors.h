#pragma once
// Synthetic binary descriptors for the place tests: prototypes ("places' landmarks") and noisy
// copies of them, so that copies of one prototype should share a word.
#include <cstdint>
#include <opencv2/core.hpp>
#include <random>
#include <vector>

namespace edgeslam::test {

inline cv::Mat randomDescriptors(int rows, std::mt19937& rng) {
  cv::Mat d(rows, 32, CV_8UC1);
  std::uniform_int_distribution<int> byte(0, 255);
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < 32; ++c) d.at<std::uint8_t>(r, c) = static_cast<std::uint8_t>(byte(rng));
  }
  return d;
}

// Row `row` of `prototypes` with `flips` distinct random bits flipped.
inline void noisyCopy(const cv::Mat& prototypes, int row, int flips, std::mt19937& rng,
                      std::uint8_t* out) {
  std::copy_n(prototypes.ptr<std::uint8_t>(row), 32, out);
  std::vector<int> bits(256);
  for (int b = 0; b < 256; ++b) bits[b] = b;
  std::shuffle(bits.begin(), bits.end(), rng);
  for (int i = 0; i < flips; ++i)
    out[bits[i] / 8] ^= static_cast<std::uint8_t>(1U << (bits[i] % 8));
}

// An "image": noisy copies of the prototype rows listed in `rows`.
inline cv::Mat imageOf(const cv::Mat& prototypes, const std::vector<int>& rows, int flips,
                       std::mt19937& rng) {
  cv::Mat d(static_cast<int>(rows.size()), 32, CV_8UC1);
  for (std::size_t i = 0; i < rows.size(); ++i) {
    noisyCopy(prototypes, rows[i], flips, rng, d.ptr<std::uint8_t>(static_cast<int>(i)));
  }
  return d;
}

// `images` images; image i shows prototypes of "place" i % places: `per_image` rows drawn from
// the place's own block of `place_rows` prototypes.
struct SyntheticScenes {
  cv::Mat prototypes;
  std::vector<cv::Mat> images;
  std::vector<std::vector<int>> rows;  // prototype rows of each image
  int places = 0;
};

inline SyntheticScenes makeScenes(int places, int place_rows, int images, int per_image, int flips,
                                  unsigned seed) {
  std::mt19937 rng(seed);
  SyntheticScenes s;
  s.places = places;
  s.prototypes = randomDescriptors(places * place_rows, rng);
  for (int i = 0; i < images; ++i) {
    const int place = i % places;
    std::vector<int> rows;
    std::uniform_int_distribution<int> pick(0, place_rows - 1);
    for (int f = 0; f < per_image; ++f) rows.push_back(place * place_rows + pick(rng));
    s.images.push_back(imageOf(s.prototypes, rows, flips, rng));
    s.rows.push_back(std::move(rows));
  }
  return s;
}

}  // namespace edgeslam::test
