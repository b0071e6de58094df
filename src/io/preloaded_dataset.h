#pragma once
// A dataset decoded into memory before the run (`run --preload`): a live camera then hands over
// frames without the client's CPU paying for the dataset's decoding (a PNG depth image costs ~7 ms
// of a 7-Scenes frame), as a device's camera driver delivers decoded frames. For experiments on a
// device with little CPU (bench/weak_device_bench.py), where reading the files would otherwise
// count against the client.
#include <cstddef>
#include <functional>
#include <memory>

#include "io/dataset.h"

namespace edgeslam {

// Reads frames 0 .. count-1 of `reader` now (with the content set on it), calling `progress(done)`
// after each; the result serves them from memory (each load a copy, so the frames stay as read)
// and throws std::out_of_range past `count`. Throws std::runtime_error, before reading further,
// when the frames would take more than half of the memory available (/proc/meminfo), naming the
// size; rethrows the reader's errors.
std::unique_ptr<DatasetReader> preloadFrames(std::unique_ptr<DatasetReader> reader,
                                             std::size_t count,
                                             const std::function<void(std::size_t)>& progress = {});

// Bytes of the images of a frame.
std::size_t frameBytes(const DatasetFrame& frame);

}  // namespace edgeslam
