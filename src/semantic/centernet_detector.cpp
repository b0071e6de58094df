#include "semantic/centernet_detector.h"

#include <algorithm>
#include <numeric>
#include <opencv2/imgproc.hpp>
#include <stdexcept>
#include <string>

#include "semantic/bgr_image.h"
#include "semantic/coco_classes.h"
#include "semantic/onnx_network.h"

namespace edgeslam {
namespace {

// The image scaled to fit input_size x input_size, centred on black: input = image * scale +
// offset.
struct Letterbox {
  cv::Mat image;
  double scale = 1.0;
  cv::Point2d offset;
};

Letterbox letterbox(const cv::Mat& bgr, int size) {
  Letterbox out;
  out.scale = static_cast<double>(size) / std::max(bgr.cols, bgr.rows);
  const cv::Size scaled(std::max(1, cvRound(bgr.cols * out.scale)),
                        std::max(1, cvRound(bgr.rows * out.scale)));
  out.offset = cv::Point2d((size - scaled.width) / 2, (size - scaled.height) / 2);
  out.image = cv::Mat::zeros(size, size, CV_8UC3);
  cv::resize(bgr,
             out.image(cv::Rect(cv::Point(cvRound(out.offset.x), cvRound(out.offset.y)), scaled)),
             scaled, 0.0, 0.0, cv::INTER_AREA);
  return out;
}

// A box within this many pixels of the image's left or right edge counts as cut off by it.
constexpr double kBorderSlackPx = 2.0;

float boxIou(const cv::Rect2f& a, const cv::Rect2f& b) {
  const float intersection = (a & b).area();
  const float united = a.area() + b.area() - intersection;
  return united > 0.0f ? intersection / united : 0.0f;
}

}  // namespace

CenterNetDetector::CenterNetDetector(const std::filesystem::path& model_file)
    : net_(loadOnnxNetwork(model_file, "CenterNet detector model")) {
  output_names_ = net_.getUnconnectedOutLayersNames();
  if (output_names_.size() != 2) {
    throw std::runtime_error("CenterNet detector model " + model_file.string() + " has " +
                             std::to_string(output_names_.size()) +
                             " outputs; expected 2 (class heat-map and box distances)");
  }
}

std::vector<Detection> CenterNetDetector::detect(const cv::Mat& image,
                                                 const CenterNetOptions& options) {
  const cv::Mat bgr = toBgr8(image);
  if (options.input_size < 64 || options.input_size % 32 != 0) {
    throw std::invalid_argument("CenterNet input size must be a multiple of 32 from 64, got " +
                                std::to_string(options.input_size));
  }
  const Letterbox box_input = letterbox(bgr, options.input_size);
  // Raw 0-255 RGB, NCHW.
  const cv::Mat blob = cv::dnn::blobFromImage(box_input.image, 1.0, cv::Size(), cv::Scalar(),
                                              /*swapRB=*/true, /*crop=*/false, CV_32F);
  net_.setInput(blob);
  std::vector<cv::Mat> outputs;
  net_.forward(outputs, output_names_);

  const int grid = options.input_size / kStride;
  const cv::Mat* heat = nullptr;
  const cv::Mat* distances = nullptr;
  for (const cv::Mat& output : outputs) {
    if (output.dims != 4 || output.size[0] != 1 || output.size[2] != grid ||
        output.size[3] != grid) {
      continue;
    }
    if (output.size[1] == kCocoClassCount) heat = &output;
    if (output.size[1] == 4) distances = &output;
  }
  if (heat == nullptr || distances == nullptr) {
    throw std::runtime_error(
        "CenterNet detector outputs are not [1,80,128,128] heat-map and [1,4,128,128] boxes");
  }

  std::vector<int> classes = options.classes;
  if (classes.empty()) {
    classes.resize(kCocoClassCount);
    std::iota(classes.begin(), classes.end(), 0);
  }
  auto plane = [grid](const cv::Mat& tensor, int channel) {
    return cv::Mat1f(grid, grid,
                     const_cast<float*>(tensor.ptr<float>(0, channel)));  // view, no copy
  };
  const cv::Mat1f left = plane(*distances, 0), top = plane(*distances, 1),
                  right = plane(*distances, 2), bottom = plane(*distances, 3);
  const cv::Rect2f image_rect(0.0f, 0.0f, static_cast<float>(bgr.cols),
                              static_cast<float>(bgr.rows));
  const cv::Mat kernel = cv::Mat::ones(3, 3, CV_8U);
  const float min_score = std::min(options.score_threshold, options.border_score_threshold);

  std::vector<Detection> detections;
  cv::Mat1f local_max;
  for (int class_id : classes) {
    const cv::Mat1f scores = plane(*heat, class_id);
    double best = 0.0;
    cv::minMaxLoc(scores, nullptr, &best);
    if (best < min_score) continue;
    cv::dilate(scores, local_max, kernel);
    for (int y = 0; y < grid; ++y) {
      for (int x = 0; x < grid; ++x) {
        const float score = scores(y, x);
        if (score < min_score || score < local_max(y, x)) continue;
        const double cx = x * kStride, cy = y * kStride;  // grid point in input pixels
        const double x0 = (cx - left(y, x) - box_input.offset.x) / box_input.scale;
        const double y0 = (cy - top(y, x) - box_input.offset.y) / box_input.scale;
        const double x1 = (cx + right(y, x) - box_input.offset.x) / box_input.scale;
        const double y1 = (cy + bottom(y, x) - box_input.offset.y) / box_input.scale;
        const bool at_border = x0 <= kBorderSlackPx || x1 >= bgr.cols - 1 - kBorderSlackPx;
        const float needed =
            class_id != kCocoPerson
                ? std::max(options.score_threshold, options.other_classes_score_threshold)
                : (at_border ? options.border_score_threshold : options.score_threshold);
        if (score < needed) continue;
        const cv::Rect2f box =
            cv::Rect2f(cv::Point2f(static_cast<float>(x0), static_cast<float>(y0)),
                       cv::Point2f(static_cast<float>(x1), static_cast<float>(y1))) &
            image_rect;
        if (box.width < 1.0f || box.height < 1.0f) continue;
        detections.push_back({class_id, score, box});
      }
    }
  }
  return classAwareNms(std::move(detections), options.nms_threshold);
}

std::vector<Detection> classAwareNms(std::vector<Detection> detections, float iou_threshold) {
  std::stable_sort(detections.begin(), detections.end(),
                   [](const Detection& a, const Detection& b) { return a.score > b.score; });
  std::vector<Detection> kept;
  for (const Detection& candidate : detections) {
    const bool suppressed = std::any_of(kept.begin(), kept.end(), [&](const Detection& k) {
      return k.class_id == candidate.class_id && boxIou(k.box, candidate.box) > iou_threshold;
    });
    if (!suppressed) kept.push_back(candidate);
  }
  return kept;
}

}  // namespace edgeslam
