// A TUM dataset's index (rgb.txt) opened as a dataset: the file list, timestamps and names are
// parsed and checked (images are not read until a frame is loaded).
#include <exception>

#include "fuzz_file.h"
#include "io/dataset.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  (void)edgeslam::fuzz::writeInput("rgb.txt", data, size);
  static const bool camera_written = [] {
    const char camera[] = "width: 640\nheight: 480\nfx: 525\nfy: 525\ncx: 319.5\ncy: 239.5\n";
    edgeslam::fuzz::writeInput("camera.yaml", reinterpret_cast<const std::uint8_t*>(camera),
                               sizeof(camera) - 1);
    return true;
  }();
  (void)camera_written;
  edgeslam::DatasetOptions options;
  options.format = edgeslam::DatasetFormat::kTum;
  try {
    (void)edgeslam::openDataset(edgeslam::fuzz::scratchDir(), options);
  } catch (const std::exception&) {
  }
  return 0;
}
