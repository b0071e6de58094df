#pragma once
// A minimal fork-join loop over std::thread for the vocabulary's training.
#include <cstddef>
#include <functional>

namespace edgeslam {

// Runs body(item, worker) for every item in [0, count) on min(threads, count) threads, the caller
// being worker 0; items are handed out one at a time in increasing order. The first exception
// thrown by a body stops the hand-out and is rethrown once every thread has finished.
void parallelFor(std::size_t count, int threads,
                 const std::function<void(std::size_t item, int worker)>& body);

// Hardware threads, at least 1.
int hardwareThreads();

}  // namespace edgeslam
