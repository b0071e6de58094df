#include "util/transparent_huge_pages.h"

#include <fstream>
#include <string>

namespace edgeslam {

bool kernelOffersTransparentHugePages() {
  std::ifstream in("/sys/kernel/mm/transparent_hugepage/enabled");
  std::string modes;
  std::getline(in, modes);
  return modes.find("[always]") != std::string::npos ||
         modes.find("[madvise]") != std::string::npos;
}

}  // namespace edgeslam
