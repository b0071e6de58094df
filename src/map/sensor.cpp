#include "map/sensor.h"

namespace edgeslam {

const char* toString(Sensor sensor) {
  switch (sensor) {
    case Sensor::kMonocular:
      return "mono";
    case Sensor::kRgbd:
      return "rgbd";
    case Sensor::kStereo:
      return "stereo";
  }
  return "?";
}

}  // namespace edgeslam
