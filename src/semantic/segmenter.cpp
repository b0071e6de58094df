#include "semantic/segmenter.h"

#include <cstdlib>
#include <stdexcept>

#include "semantic/centernet_selfie_segmenter.h"

#ifndef EDGESLAM_DEFAULT_SHARED_DIR
#define EDGESLAM_DEFAULT_SHARED_DIR "../shared"
#endif

namespace edgeslam {

std::filesystem::path defaultModelDirectory() {
  if (const char* env = std::getenv("EDGESLAM_SHARED"); env != nullptr && *env != '\0') {
    return std::filesystem::path(env) / "models";
  }
  return std::filesystem::path(EDGESLAM_DEFAULT_SHARED_DIR) / "models";
}

std::vector<std::string> segmenterBackends() {
  return {"centernet-selfie"};
}

std::unique_ptr<Segmenter> makeSegmenter(const SegmenterOptions& options) {
  if (options.backend == "centernet-selfie") {
    return std::make_unique<CenterNetSelfieSegmenter>(options);
  }
  std::string known;
  for (const auto& name : segmenterBackends()) known += (known.empty() ? "" : ", ") + name;
  throw std::invalid_argument("unknown segmenter backend '" + options.backend +
                              "' (known: " + known + ")");
}

}  // namespace edgeslam
