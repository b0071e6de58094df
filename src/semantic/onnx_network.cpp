#include "semantic/onnx_network.h"

#include <stdexcept>
#include <string>

namespace edgeslam {

cv::dnn::Net loadOnnxNetwork(const std::filesystem::path& path, const char* what) {
  std::error_code error;
  if (!std::filesystem::is_regular_file(path, error)) {
    throw std::runtime_error(std::string(what) + " not found: " + path.string() +
                             " (set --models or EDGESLAM_SHARED to the folder holding models/)");
  }
  cv::dnn::Net net;
  try {
    net = cv::dnn::readNetFromONNX(path.string());
  } catch (const cv::Exception& e) {
    throw std::runtime_error(std::string(what) + " " + path.string() +
                             " is not a network OpenCV DNN can read: " + e.msg);
  }
  if (net.empty()) {
    throw std::runtime_error(std::string(what) + " " + path.string() + " holds no network");
  }
  net.setPreferableBackend(cv::dnn::DNN_BACKEND_OPENCV);
  net.setPreferableTarget(cv::dnn::DNN_TARGET_CPU);
  return net;
}

}  // namespace edgeslam
