#include "optimize/camera_projection.h"

#include <cmath>
#include <stdexcept>
#include <string>

namespace edgeslam {

CameraProjection CameraProjection::fromCamera(const PinholeCamera& camera, double bf) {
  CameraProjection projection{camera.fx(), camera.fy(), camera.cx(), camera.cy(), bf};
  if (bf < 0.0) projection.bf = camera.fx() * camera.intrinsics().baseline_m;
  projection.validate();
  return projection;
}

void CameraProjection::validate() const {
  const auto require = [](bool ok, const char* name, double value) {
    if (!ok) {
      throw std::invalid_argument(std::string("CameraProjection: invalid ") + name + " = " +
                                  std::to_string(value));
    }
  };
  require(std::isfinite(fx) && fx > 0.0, "fx", fx);
  require(std::isfinite(fy) && fy > 0.0, "fy", fy);
  require(std::isfinite(cx), "cx", cx);
  require(std::isfinite(cy), "cy", cy);
  require(std::isfinite(bf) && bf >= 0.0, "bf", bf);
}

}  // namespace edgeslam
