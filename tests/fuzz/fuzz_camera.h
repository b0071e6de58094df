#pragma once
// The session camera the image checks of the harnesses compare against.
#include "geometry/camera.h"

namespace edgeslam::fuzz {

inline const PinholeCamera& camera() {
  static const PinholeCamera kCamera = [] {
    CameraIntrinsics in;
    in.width = 640;
    in.height = 480;
    in.fx = in.fy = 525.0;
    in.cx = 319.5;
    in.cy = 239.5;
    return PinholeCamera(in);
  }();
  return kCamera;
}

}  // namespace edgeslam::fuzz
