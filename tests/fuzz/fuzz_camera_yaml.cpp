// Camera files (`--camera FILE.yaml`): a refusal is std::exception (bad values, unknown keys,
// YAML syntax); a crash or a sanitizer report is a bug.
#include <exception>

#include "fuzz_file.h"
#include "io/camera_file.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto path = edgeslam::fuzz::writeInput("camera.yaml", data, size);
  try {
    (void)edgeslam::loadCameraFile(path);
  } catch (const std::exception&) {
  }
  return 0;
}
