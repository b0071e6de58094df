#include "semantic/person_mask_model.h"

#include <opencv2/imgproc.hpp>
#include <stdexcept>

#include "semantic/onnx_network.h"

namespace edgeslam {

PersonMaskModel::PersonMaskModel(const std::filesystem::path& model_file)
    : net_(loadOnnxNetwork(model_file, "person mask (selfie) model")) {}

cv::Mat1f PersonMaskModel::probability(const cv::Mat& bgr, const cv::Rect& crop) {
  const cv::Rect inside = crop & cv::Rect(0, 0, bgr.cols, bgr.rows);
  if (inside.empty()) return cv::Mat1f::zeros(std::max(crop.height, 0), std::max(crop.width, 0));
  const double scale = static_cast<double>(kInputSize) / std::max(inside.width, inside.height);
  const cv::Size scaled(std::max(1, cvRound(inside.width * scale)),
                        std::max(1, cvRound(inside.height * scale)));
  const cv::Point offset((kInputSize - scaled.width) / 2, (kInputSize - scaled.height) / 2);
  cv::Mat input = cv::Mat::zeros(kInputSize, kInputSize, CV_8UC3);
  cv::resize(bgr(inside), input(cv::Rect(offset, scaled)), scaled, 0.0, 0.0, cv::INTER_AREA);

  const cv::Mat blob = cv::dnn::blobFromImage(input, 1.0 / 255.0, cv::Size(), cv::Scalar(),
                                              /*swapRB=*/true, /*crop=*/false, CV_32F);
  net_.setInput(blob);
  const cv::Mat output = net_.forward();
  if (output.total() != static_cast<std::size_t>(kInputSize) * kInputSize) {
    throw std::runtime_error("person mask model output has " + std::to_string(output.total()) +
                             " values; expected 256x256");
  }
  const cv::Mat1f square(kInputSize, kInputSize, const_cast<float*>(output.ptr<float>()));
  cv::Mat1f result;
  cv::resize(square(cv::Rect(offset, scaled)), result, inside.size(), 0.0, 0.0, cv::INTER_LINEAR);
  return result;
}

}  // namespace edgeslam
