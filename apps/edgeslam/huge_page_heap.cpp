#include "huge_page_heap.h"

#include <unistd.h>

#include <cstdlib>
#include <string>

#include "util/transparent_huge_pages.h"

namespace edgeslam::cli {
namespace {

#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
constexpr bool kSanitized = true;
#elif defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(thread_sanitizer) || \
    __has_feature(memory_sanitizer)
constexpr bool kSanitized = true;
#else
constexpr bool kSanitized = false;
#endif
#else
constexpr bool kSanitized = false;
#endif

constexpr const char* kTunable = "glibc.malloc.hugetlb";

// The sub-command named on the command line ("" for none): the first word that is neither an
// option nor the value of the one global option that takes a value.
std::string subcommand(char** argv) {
  for (int i = 1; argv[i] != nullptr; ++i) {
    const std::string word = argv[i];
    if (word == "--log-level") {
      if (argv[i + 1] == nullptr) break;
      ++i;
    } else if (!word.starts_with("-")) {
      return word;
    }
  }
  return "";
}

}  // namespace

void restartWithHugePageHeap(char** argv) {
  if (kSanitized) return;
  // A restart costs a second start of the binary (~0.25 s of loading its libraries here): worth it
  // for the commands that hold maps, not for the quick ones.
  const std::string command = subcommand(argv);
  if (command != "server" && command != "run" && command != "client" && command != "map") return;
  if (const char* off = std::getenv("EDGESLAM_HUGE_PAGES");
      off != nullptr && std::string(off) == "0") {
    return;
  }
  const char* existing = std::getenv("GLIBC_TUNABLES");
  std::string tunables = existing != nullptr ? existing : "";
  if (tunables.find(kTunable) != std::string::npos) return;  // set: by us or by the user
  if (!kernelOffersTransparentHugePages()) return;
  tunables += (tunables.empty() ? "" : ":") + std::string(kTunable) + "=1";
  if (setenv("GLIBC_TUNABLES", tunables.c_str(), 1) != 0) return;
  execv("/proc/self/exe", argv);
  // Not restarted (no /proc, say): go on as started, and do not leave the tunable claimed.
  if (existing != nullptr) {
    setenv("GLIBC_TUNABLES", existing, 1);
  } else {
    unsetenv("GLIBC_TUNABLES");
  }
}

}  // namespace edgeslam::cli
