#pragma once
// Loading an ONNX network with OpenCV DNN, with errors that name the file.
#include <filesystem>
#include <opencv2/dnn.hpp>

namespace edgeslam {

// Throws std::runtime_error naming `path` when it is missing, not a file, or not a network OpenCV
// can parse. `what` describes the model's role ("detector model") for the message.
cv::dnn::Net loadOnnxNetwork(const std::filesystem::path& path, const char* what);

}  // namespace edgeslam
