#include "util/thread_priority.h"

#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <cerrno>

namespace edgeslam {
namespace {

// On Linux, PRIO_PROCESS with a thread id sets that one thread's nice value.
id_t currentThreadId() {
  return static_cast<id_t>(::syscall(SYS_gettid));
}

}  // namespace

int currentThreadNice() {
  errno = 0;
  return ::getpriority(PRIO_PROCESS, currentThreadId());
}

bool lowerCurrentThreadPriority(int increment) {
  if (increment <= 0) return increment == 0;
  const int target = currentThreadNice() + increment;
  return ::setpriority(PRIO_PROCESS, currentThreadId(), target) == 0;
}

}  // namespace edgeslam
