#include "util/failpoint.h"

#include <fmt/format.h>

#include <atomic>
#include <cstdlib>
#include <map>
#include <stdexcept>
#include <string>

#include "util/mutex.h"

namespace edgeslam {
namespace {

struct Armed {
  std::size_t at_call = 0;
  std::size_t calls = 0;
};

class Failpoints {
 public:
  Failpoints() {
    const char* spec = std::getenv("EDGESLAM_FAILPOINTS");
    if (spec == nullptr) return;
    std::string_view rest(spec);
    while (!rest.empty()) {
      const std::size_t comma = rest.find(',');
      const std::string_view item = rest.substr(0, comma);
      rest = comma == std::string_view::npos ? std::string_view() : rest.substr(comma + 1);
      const std::size_t at = item.find('@');
      if (at == std::string_view::npos) continue;
      const std::size_t n = std::strtoull(std::string(item.substr(at + 1)).c_str(), nullptr, 10);
      if (n > 0) armed_[std::string(item.substr(0, at))] = {n, 0};
    }
    any_ = !armed_.empty();
  }

  void hit(std::string_view name) {
    if (!any_.load(std::memory_order_relaxed)) return;
    MutexLock lock(mutex_);
    const auto found = armed_.find(std::string(name));
    if (found == armed_.end()) return;
    if (++found->second.calls != found->second.at_call) return;
    throw std::runtime_error(fmt::format("fault injected at {} (call {}, EDGESLAM_FAILPOINTS)",
                                         name, found->second.calls));
  }

 private:
  std::atomic<bool> any_{false};
  Mutex mutex_;
  std::map<std::string, Armed> armed_ GUARDED_BY(mutex_);
};

}  // namespace

void failpoint(std::string_view name) {
  static Failpoints failpoints;
  failpoints.hit(name);
}

}  // namespace edgeslam
