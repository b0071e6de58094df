#pragma once
// `run --repeat N`: what each pass of the sequence did and what the map and the process held at
// its end (metrics.json "passes"), to show that a map revisiting the same place stays bounded.
#include <cstddef>
#include <cstdint>
#include <functional>
#include <nlohmann/json.hpp>
#include <optional>
#include <vector>

#include "client/tracking_types.h"
#include "eval/alignment.h"
#include "io/trajectory.h"

namespace edgeslam {
class SlamSystem;
}

namespace edgeslam::cli {

// The edge session's map where the client does not report it (offload).
struct EdgeMapSize {
  std::size_t keyframes = 0;
  std::size_t points = 0;
};

struct PassRecord {
  std::size_t first_frame = 0;  // run-wide frame indices, inclusive
  std::size_t last_frame = 0;
  double first_timestamp = 0.0;
  double last_timestamp = 0.0;
  std::size_t frames = 0;  // frames tracked (not skipped, not dropped late)
  std::size_t tracked = 0;
  std::size_t lost = 0;
  std::size_t relocalized = 0;
  std::size_t keyframes_made = 0;  // by the client's tracker in this pass
  std::size_t map_keyframes = 0;   // in the (edge's) map at the end of the pass
  std::size_t map_points = 0;
  std::size_t map_resets = 0;  // in the run so far
  std::uint64_t rss_bytes = 0;
  std::uint64_t peak_rss_bytes = 0;
  std::uint64_t heap_in_use_bytes = 0;  // malloc's allocated bytes (live objects, not free chunks)
  // The least heap in use sampled over the pass's second half: what the process keeps, without
  // the work in flight at one instant (a local BA's problem, a slice being built), which swings
  // the end-of-pass sample by ~15 MB in RGB-D.
  std::uint64_t heap_floor_bytes = 0;
  double wall_s = 0.0;
};

class PassLog {
 public:
  explicit PassLog(std::size_t frames_per_pass) : frames_per_pass_(frames_per_pass) {}

  void addFrame(std::size_t index, double timestamp, const TrackResult& result);
  // Call before each frame (frames skipped late are never seen, so a pass may end on any frame):
  // closes the open pass when frame `index` belongs to a later one. finish() closes the last.
  // The map's size is what `edge_map` says when it says something (asked at pass ends only),
  // else the SlamSystem's.
  void beforeFrame(std::size_t index, const SlamSystem& slam,
                   const std::function<std::optional<EdgeMapSize>()>& edge_map, double wall_s);
  void finish(const SlamSystem& slam, const std::function<std::optional<EdgeMapSize>()>& edge_map,
              double wall_s);

  const std::vector<PassRecord>& passes() const { return passes_; }
  // One entry per pass, with its ATE (own alignment, and within the whole run's alignment, which
  // shows that the passes share one frame).
  nlohmann::json json(const Trajectory& ground_truth, const Trajectory& estimate,
                      AlignMode align) const;
  // One line per pass for the run's summary.
  void print() const;

 private:
  PassRecord& current(std::size_t index, double timestamp);
  void close(const SlamSystem& slam, const std::function<std::optional<EdgeMapSize>()>& edge_map,
             double wall_s);

  // Every this many frames in a pass's second half (mallinfo2 walks every arena's free lists).
  static constexpr std::size_t kHeapSampleEvery = 5;

  std::size_t frames_per_pass_;
  std::vector<PassRecord> passes_;
  bool open_ = false;
};

}  // namespace edgeslam::cli
