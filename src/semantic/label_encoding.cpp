#include "semantic/label_encoding.h"

#include <charconv>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

namespace edgeslam {
namespace {

constexpr const char* kEmpty = "empty";
constexpr const char* kPngPrefix = "png/";

cv::Size reducedSize(cv::Size full, int downscale) {
  return {(full.width + downscale - 1) / downscale, (full.height + downscale - 1) / downscale};
}

int parseDownscale(const std::string& encoding) {
  const std::string prefix = kPngPrefix;
  int downscale = 0;
  if (encoding.rfind(prefix, 0) == 0) {
    const char* first = encoding.data() + prefix.size();
    const char* last = encoding.data() + encoding.size();
    const auto [end, error] = std::from_chars(first, last, downscale);
    if (error == std::errc() && end == last && downscale >= 1) return downscale;
  }
  throw std::invalid_argument("unknown label image encoding '" + encoding +
                              "' (expected 'empty' or 'png/N')");
}

}  // namespace

std::vector<std::uint8_t> encodeLabelImage(const cv::Mat1b& labels, int downscale,
                                           std::string& encoding) {
  if (labels.empty()) throw std::invalid_argument("cannot encode an empty label image");
  if (downscale < 1) {
    throw std::invalid_argument("label image downscale must be >= 1, got " +
                                std::to_string(downscale));
  }
  if (cv::countNonZero(labels) == 0) {
    encoding = kEmpty;
    return {};
  }
  cv::Mat1b reduced = labels;
  if (downscale > 1) {
    cv::resize(labels, reduced, reducedSize(labels.size(), downscale), 0.0, 0.0, cv::INTER_NEAREST);
  }
  std::vector<std::uint8_t> bytes;
  // Strongest zlib level with the filter strategy suited to few large flat regions.
  const std::vector<int> parameters = {cv::IMWRITE_PNG_COMPRESSION, 9, cv::IMWRITE_PNG_STRATEGY,
                                       cv::IMWRITE_PNG_STRATEGY_RLE};
  if (!cv::imencode(".png", reduced, bytes, parameters)) {
    throw std::runtime_error("PNG encoding of a label image failed");
  }
  encoding = kPngPrefix + std::to_string(downscale);
  return bytes;
}

cv::Mat1b decodeLabelImage(const std::vector<std::uint8_t>& bytes, const std::string& encoding,
                           cv::Size full_size) {
  if (full_size.width <= 0 || full_size.height <= 0) {
    throw std::invalid_argument("label image decoding needs a positive full size");
  }
  if (encoding == kEmpty) return cv::Mat1b::zeros(full_size);
  const int downscale = parseDownscale(encoding);
  const cv::Mat decoded = cv::imdecode(bytes, cv::IMREAD_UNCHANGED);
  const cv::Size expected = reducedSize(full_size, downscale);
  if (decoded.empty() || decoded.type() != CV_8UC1 || decoded.size() != expected) {
    throw std::invalid_argument("label image bytes (" + std::to_string(bytes.size()) +
                                ") are not an 8-bit PNG of " + std::to_string(expected.width) +
                                "x" + std::to_string(expected.height));
  }
  if (downscale == 1) return decoded;
  cv::Mat1b full;
  cv::resize(decoded, full, full_size, 0.0, 0.0, cv::INTER_NEAREST);
  return full;
}

}  // namespace edgeslam
