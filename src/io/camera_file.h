#pragma once
// Camera files: plain YAML (a JSON object is valid too) with the keys
//   width, height, fx, fy, cx, cy                 (required)
//   k1, k2, p1, p2, k3                            (optional radial-tangential distortion, default
//   0) depth_factor, baseline_m, fps                 (optional, default 0 = none / unknown)
// Unknown keys are an error so that typos are caught.
#include <filesystem>

#include "geometry/camera.h"

namespace edgeslam {

// Throws DatasetError naming the file (and line) on a missing file, unknown or missing key,
// non-numeric value or intrinsics that make no sense.
CameraIntrinsics loadCameraFile(const std::filesystem::path& path);

// Writes every required key and the optional ones that are non-zero; loadCameraFile reads it back
// exactly. Throws DatasetError when the file cannot be written.
void saveCameraFile(const std::filesystem::path& path, const CameraIntrinsics& intrinsics);

}  // namespace edgeslam
