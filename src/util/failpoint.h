#pragma once
// Faults injected on purpose, for the tests that show a failing worker ends its own session and
// nothing else. EDGESLAM_FAILPOINTS="name@N[,name@N...]" makes the Nth call of failpoint("name")
// in the process throw (once); unset, a failpoint costs one relaxed atomic load.
#include <string_view>

namespace edgeslam {

void failpoint(std::string_view name);

}  // namespace edgeslam
