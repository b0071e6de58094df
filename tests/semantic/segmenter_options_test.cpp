// Segmenter construction errors that need no model files.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>

#include "semantic/segmenter.h"

namespace edgeslam {
namespace {

namespace fs = std::filesystem;

std::string errorOf(const SegmenterOptions& options) {
  try {
    makeSegmenter(options);
  } catch (const std::exception& e) {
    return e.what();
  }
  return "";
}

TEST(SegmenterOptions, MissingModelNamesTheFile) {
  SegmenterOptions options;
  options.model_dir = "/nonexistent/models";
  const std::string message = errorOf(options);
  EXPECT_NE(message.find("/nonexistent/models/centernet_mbv3_coco_512.onnx"), std::string::npos)
      << message;
  EXPECT_NE(message.find("not found"), std::string::npos) << message;
  EXPECT_THROW(makeSegmenter(options), std::runtime_error);
}

TEST(SegmenterOptions, MalformedModelNamesTheFile) {
  const fs::path folder =
      fs::temp_directory_path() / ("edgeslam_semantic_" + std::to_string(::getpid()));
  fs::create_directories(folder);
  const fs::path bad = folder / "garbage.onnx";
  std::ofstream(bad) << "this is not a protobuf network";
  SegmenterOptions options;
  options.detector_model = bad;
  const std::string message = errorOf(options);
  fs::remove_all(folder);
  EXPECT_NE(message.find(bad.string()), std::string::npos) << message;
}

TEST(SegmenterOptions, UnknownBackendIsAnError) {
  SegmenterOptions options;
  options.backend = "mask-rcnn";
  const std::string message = errorOf(options);
  EXPECT_NE(message.find("mask-rcnn"), std::string::npos) << message;
  EXPECT_NE(message.find("centernet-selfie"), std::string::npos) << message;
}

TEST(SegmenterOptions, DefaultModelDirectoryFollowsEdgeslamShared) {
  const char* previous = std::getenv("EDGESLAM_SHARED");
  const std::string saved = previous ? previous : "";
  ::setenv("EDGESLAM_SHARED", "/somewhere/shared", 1);
  EXPECT_EQ(defaultModelDirectory(), fs::path("/somewhere/shared/models"));
  if (previous) {
    ::setenv("EDGESLAM_SHARED", saved.c_str(), 1);
  } else {
    ::unsetenv("EDGESLAM_SHARED");
  }
  EXPECT_EQ(defaultModelDirectory().filename(), "models");
}

}  // namespace
}  // namespace edgeslam
