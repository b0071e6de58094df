#pragma once

namespace edgeslam {

enum class Sensor { kMonocular, kRgbd, kStereo };

const char* toString(Sensor sensor);

}  // namespace edgeslam
