// Ground-truth and estimate files: TUM trajectories, KITTI pose files and KITTI times files; the
// first byte picks the reader, the rest is the file.
#include <exception>

#include "fuzz_file.h"
#include "io/trajectory.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const auto path = edgeslam::fuzz::writeInput("trajectory.txt", data + 1, size - 1);
  try {
    switch (data[0] % 3) {
      case 0:
        (void)edgeslam::readTumTrajectory(path);
        break;
      case 1:
        (void)edgeslam::readKittiPoses(path);
        break;
      default:
        (void)edgeslam::readTimes(path);
        break;
    }
  } catch (const std::exception&) {
  }
  return 0;
}
