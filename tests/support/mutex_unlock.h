#pragma once
// Lets go of a Mutex the test holds for a scope and takes it back at its end: a test that holds a
// map's mutex for its body calls code that takes the mutex itself (applySlice, a bundle
// adjustment) inside one of these. The clang build checks both ends like any other lock.
#include "util/mutex.h"
#include "util/thread_annotations.h"

namespace edgeslam::test {

class SCOPED_CAPABILITY MutexUnlock {
 public:
  explicit MutexUnlock(Mutex& mutex) RELEASE(mutex) : mutex_(mutex) { mutex_.unlock(); }
  ~MutexUnlock() RELEASE() { mutex_.lock(); }
  MutexUnlock(const MutexUnlock&) = delete;
  MutexUnlock& operator=(const MutexUnlock&) = delete;

 private:
  Mutex& mutex_;
};

}  // namespace edgeslam::test
