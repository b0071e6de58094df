// Compiled (never linked) by the MapLockCheck tests of the clang build (tests/map/CMakeLists.txt):
// a Map method called without the map's mutex must not compile there (-Wthread-safety, an error
// with the project's -Werror), and the same call with the mutex held must.
#include "map/map.h"

namespace edgeslam {

std::size_t countPoints(const Map& map) {
#ifdef EDGESLAM_MAP_LOCK_HELD
  MutexLock lock(map.updateMutex());
#endif
  return map.pointCount();
}

}  // namespace edgeslam
