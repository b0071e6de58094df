#pragma once
// Compact wire encoding of a label image (or a binary mask): nearest-neighbour downscaling by an
// integer factor, then lossless PNG. An all-zero image is sent as no bytes at all.
#include <cstdint>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

namespace edgeslam {

// Encodes `labels` (CV_8U). `downscale` >= 1 divides both sides (rounded up). Sets `encoding` to
// what decodeLabelImage needs to know: "png/N" (N = downscale) or "empty".
// Throws std::invalid_argument for an empty image or downscale < 1.
std::vector<std::uint8_t> encodeLabelImage(const cv::Mat1b& labels, int downscale,
                                           std::string& encoding);

// The label image back at `full_size` (nearest-neighbour upscaling). Throws std::invalid_argument
// for an unknown encoding or bytes that are not a PNG of the expected reduced size.
cv::Mat1b decodeLabelImage(const std::vector<std::uint8_t>& bytes, const std::string& encoding,
                           cv::Size full_size);

}  // namespace edgeslam
