#include "place/vocabulary_training.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>

#include "place/bit_majority.h"
#include "place/parallel_for.h"
#include "util/mutex.h"

namespace edgeslam {
namespace {

constexpr std::size_t kChunk = 16384;  // descriptors per parallel assignment task
// Nodes with at least this many descriptors are clustered one at a time with their assignment
// split across threads; smaller ones are handed out whole, one per thread.
constexpr std::size_t kParallelNodeSize = 65536;
constexpr std::uint16_t kUnassigned = 0xFFFF;

std::uint64_t splitMix64(std::uint64_t x) {
  x += 0x9e3779b97f4a7c15ULL;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
  return x ^ (x >> 31);
}

struct Workspace {
  std::vector<std::uint16_t> assignment;
  std::vector<std::uint32_t> min_distance2;
  std::vector<Descriptor256> descriptor_buffer;
  std::vector<std::uint32_t> image_buffer;
};

// A node's children: their centres, and how many descriptors each has; after the split the
// node's range holds the children's descriptors one child after the other. No centres: the node
// is a leaf.
struct NodeSplit {
  std::vector<Descriptor256> centres;
  std::vector<std::size_t> sizes;
};

// k-means++: each further centre drawn with probability proportional to its squared distance to
// the closest centre so far. Stops early when every descriptor equals some centre.
std::vector<Descriptor256> seedCentres(std::span<const Descriptor256> d, int k,
                                       std::mt19937_64& rng, std::vector<std::uint32_t>& min_d2) {
  const std::size_t n = d.size();
  std::vector<Descriptor256> centres;
  centres.push_back(d[rng() % n]);
  min_d2.resize(n);
  std::uint64_t total = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const auto distance = static_cast<std::uint32_t>(hammingDistance(d[i], centres[0]));
    min_d2[i] = distance * distance;
    total += min_d2[i];
  }
  while (static_cast<int>(centres.size()) < k && total > 0) {
    const std::uint64_t target = rng() % total;
    std::uint64_t cumulative = 0;
    std::size_t chosen = n - 1;
    for (std::size_t i = 0; i < n; ++i) {
      cumulative += min_d2[i];
      if (cumulative > target) {
        chosen = i;
        break;
      }
    }
    centres.push_back(d[chosen]);
    total = 0;
    for (std::size_t i = 0; i < n; ++i) {
      const auto distance = static_cast<std::uint32_t>(hammingDistance(d[i], centres.back()));
      min_d2[i] = std::min(min_d2[i], distance * distance);
      total += min_d2[i];
    }
  }
  return centres;
}

// Assigns descriptors [begin, end) to their closest centre (the lowest index on ties), counting
// bits per centre into `counters`; returns how many assignments changed.
std::size_t assignRange(std::span<const Descriptor256> d, std::span<const Descriptor256> centres,
                        std::span<std::uint16_t> assignment, std::size_t begin, std::size_t end,
                        std::vector<BitMajority>& counters) {
  std::size_t changed = 0;
  const std::size_t k = centres.size();
  for (std::size_t i = begin; i < end; ++i) {
    std::uint16_t best = 0;
    int best_distance = hammingDistance(d[i], centres[0]);
    for (std::size_t c = 1; c < k; ++c) {
      const int distance = hammingDistance(d[i], centres[c]);
      if (distance < best_distance) {
        best_distance = distance;
        best = static_cast<std::uint16_t>(c);
      }
    }
    changed += assignment[i] != best ? 1 : 0;
    assignment[i] = best;
    counters[best].add(d[i]);
  }
  return changed;
}

// Chunks are fixed by size, not by thread count, and bit counts are integer sums, so the result
// does not depend on `threads`.
std::size_t assignAll(std::span<const Descriptor256> d, std::span<const Descriptor256> centres,
                      std::span<std::uint16_t> assignment, std::vector<BitMajority>& counters,
                      int threads) {
  const std::size_t n = d.size();
  counters.assign(centres.size(), BitMajority{});
  const std::size_t chunks = (n + kChunk - 1) / kChunk;
  if (threads <= 1 || chunks <= 1) return assignRange(d, centres, assignment, 0, n, counters);
  std::vector<std::vector<BitMajority>> partial(chunks, std::vector<BitMajority>(centres.size()));
  std::vector<std::size_t> changed(chunks, 0);
  parallelFor(chunks, threads, [&](std::size_t chunk, int) {
    const std::size_t begin = chunk * kChunk;
    changed[chunk] =
        assignRange(d, centres, assignment, begin, std::min(n, begin + kChunk), partial[chunk]);
  });
  std::size_t total_changed = 0;
  for (std::size_t chunk = 0; chunk < chunks; ++chunk) {
    total_changed += changed[chunk];
    for (std::size_t c = 0; c < centres.size(); ++c) counters[c].merge(partial[chunk][c]);
  }
  return total_changed;
}

// Clusters one node's descriptors into at most k children and reorders the node's range child by
// child (stable). The root always gets children; another node with fewer than two non-empty
// clusters stays a leaf.
NodeSplit splitNode(std::span<Descriptor256> d, std::span<std::uint32_t> images, int k,
                    int max_iterations, std::uint64_t seed, bool is_root, int threads,
                    Workspace& ws) {
  const std::size_t n = d.size();
  ws.assignment.assign(n, kUnassigned);
  std::span<std::uint16_t> assignment(ws.assignment);
  std::vector<Descriptor256> centres;
  if (n <= static_cast<std::size_t>(k)) {
    for (std::size_t i = 0; i < n; ++i) {
      const auto same = std::find(centres.begin(), centres.end(), d[i]);
      assignment[i] = static_cast<std::uint16_t>(same - centres.begin());
      if (same == centres.end()) centres.push_back(d[i]);
    }
  } else {
    std::mt19937_64 rng(seed);
    centres = seedCentres(d, k, rng, ws.min_distance2);
    std::vector<BitMajority> counters;
    assignAll(d, centres, assignment, counters, threads);
    for (int iteration = 1; iteration < max_iterations; ++iteration) {
      std::vector<Descriptor256> updated = centres;
      for (std::size_t c = 0; c < centres.size(); ++c) {
        if (counters[c].count() > 0) updated[c] = counters[c].majority();
      }
      if (updated == centres) break;
      centres = std::move(updated);
      if (assignAll(d, centres, assignment, counters, threads) == 0) break;
    }
  }

  std::vector<std::size_t> sizes(centres.size(), 0);
  for (const std::uint16_t a : assignment) ++sizes[a];
  std::vector<std::uint16_t> compact(centres.size(), kUnassigned);
  NodeSplit split;
  for (std::size_t c = 0; c < centres.size(); ++c) {
    if (sizes[c] == 0) continue;
    compact[c] = static_cast<std::uint16_t>(split.centres.size());
    split.centres.push_back(centres[c]);
    split.sizes.push_back(sizes[c]);
  }
  if (split.centres.size() < 2 && !is_root) return {};

  std::vector<std::size_t> next(split.sizes.size(), 0);
  for (std::size_t c = 1; c < next.size(); ++c) next[c] = next[c - 1] + split.sizes[c - 1];
  ws.descriptor_buffer.resize(n);
  ws.image_buffer.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t to = next[compact[assignment[i]]]++;
    ws.descriptor_buffer[to] = d[i];
    ws.image_buffer[to] = images[i];
  }
  std::copy_n(ws.descriptor_buffer.begin(), n, d.begin());
  std::copy_n(ws.image_buffer.begin(), n, images.begin());
  return split;
}

struct Range {
  std::size_t begin = 0;
  std::size_t end = 0;
  std::size_t size() const { return end - begin; }
};

struct PendingNode {
  NodeId id = 0;
  int depth = 0;
};

// Serialises the clustering progress calls of the workers.
class ProgressReporter {
 public:
  ProgressReporter(const VocabularyTrainingOptions& options, std::size_t total)
      : callback_(options.progress), total_(total) {}
  void advance(std::size_t amount) {
    if (!callback_ || amount == 0) return;
    const MutexLock lock(mutex_);
    done_ += amount;
    callback_({"clustering", std::min(done_, total_), total_});
  }

 private:
  const std::function<void(const VocabularyTrainingProgress&)>& callback_;
  Mutex mutex_;
  std::size_t done_ GUARDED_BY(mutex_) = 0;
  std::size_t total_;
};

// idf of every leaf from the training images its descriptors came from.
void weighLeaves(VocabularyTree& tree, const std::vector<Range>& ranges,
                 const std::vector<std::uint32_t>& images, std::size_t image_count) {
  std::vector<bool> has_children(tree.parents.size(), false);
  for (std::size_t i = 1; i < tree.parents.size(); ++i) has_children[tree.parents[i]] = true;
  std::vector<std::uint32_t> last_seen_in(image_count, std::numeric_limits<std::uint32_t>::max());
  for (std::size_t node = 1; node < tree.parents.size(); ++node) {
    if (has_children[node]) continue;
    std::size_t images_with_word = 0;
    for (std::size_t i = ranges[node].begin; i < ranges[node].end; ++i) {
      if (last_seen_in[images[i]] != node) {
        last_seen_in[images[i]] = static_cast<std::uint32_t>(node);
        ++images_with_word;
      }
    }
    tree.weights[node] = std::log(static_cast<double>(image_count) /
                                  static_cast<double>(std::max<std::size_t>(images_with_word, 1)));
  }
}

}  // namespace

void VocabularyTrainingOptions::validate() const {
  if (branching < 2 || branching > 256) {
    throw std::invalid_argument(fmt::format("branching (k) {} outside [2, 256]", branching));
  }
  if (levels < 1 || levels > 16) {
    throw std::invalid_argument(fmt::format("levels (L) {} outside [1, 16]", levels));
  }
  if (max_iterations < 1) {
    throw std::invalid_argument(
        fmt::format("max_iterations {} must be at least 1", max_iterations));
  }
  if (threads < 0) throw std::invalid_argument(fmt::format("threads {} is negative", threads));
  (void)toString(weighting);
}

Vocabulary trainVocabulary(std::span<const cv::Mat> image_descriptors,
                           const VocabularyTrainingOptions& options) {
  options.validate();
  const int threads = options.threads == 0 ? hardwareThreads() : options.threads;
  if (image_descriptors.size() >= std::numeric_limits<std::uint32_t>::max()) {
    throw std::invalid_argument("too many training images");
  }
  std::size_t total = 0;
  for (std::size_t i = 0; i < image_descriptors.size(); ++i) {
    const cv::Mat& m = image_descriptors[i];
    if (m.empty()) continue;
    if (m.type() != CV_8UC1 || m.cols != kDescriptorBytes) {
      throw std::invalid_argument(
          fmt::format("training image {}: descriptors must be CV_8UC1 with {} columns, got type "
                      "{} with {} columns",
                      i, kDescriptorBytes, m.type(), m.cols));
    }
    total += static_cast<std::size_t>(m.rows);
  }
  if (total == 0) throw std::invalid_argument("no training descriptors");

  std::vector<Descriptor256> descriptors;
  std::vector<std::uint32_t> images;
  descriptors.reserve(total);
  images.reserve(total);
  for (std::size_t i = 0; i < image_descriptors.size(); ++i) {
    const cv::Mat& m = image_descriptors[i];
    for (int r = 0; r < m.rows; ++r) {
      descriptors.push_back(Descriptor256::fromBytes(m.ptr<std::uint8_t>(r)));
      images.push_back(static_cast<std::uint32_t>(i));
    }
  }

  VocabularyTree tree;
  tree.branching = options.branching;
  tree.levels = options.levels;
  tree.weighting = options.weighting;
  tree.training_images = image_descriptors.size();
  tree.training_descriptors = total;
  tree.parents.push_back(kNoParent);
  tree.centres.emplace_back();
  tree.weights.push_back(0.0);
  std::vector<Range> ranges = {{0, total}};

  const std::size_t levels = static_cast<std::size_t>(options.levels);
  ProgressReporter progress(options, total * levels);
  std::vector<Workspace> workspaces(static_cast<std::size_t>(threads));
  std::vector<PendingNode> level = {{0, 0}};
  while (!level.empty()) {
    std::vector<NodeSplit> splits(level.size());
    const auto process = [&](std::size_t i, int worker, int inner_threads) {
      const Range range = ranges[level[i].id];
      splits[i] =
          splitNode(std::span(descriptors).subspan(range.begin, range.size()),
                    std::span(images).subspan(range.begin, range.size()), options.branching,
                    options.max_iterations, splitMix64(options.seed ^ splitMix64(level[i].id)),
                    level[i].id == 0, inner_threads, workspaces[static_cast<std::size_t>(worker)]);
      const std::size_t levels_done =
          splits[i].centres.empty() ? levels - static_cast<std::size_t>(level[i].depth) : 1;
      progress.advance(range.size() * levels_done);
    };
    std::vector<std::size_t> small;
    for (std::size_t i = 0; i < level.size(); ++i) {
      if (threads > 1 && ranges[level[i].id].size() >= kParallelNodeSize) {
        process(i, 0, threads);
      } else {
        small.push_back(i);
      }
    }
    parallelFor(small.size(), threads,
                [&](std::size_t j, int worker) { process(small[j], worker, 1); });

    std::vector<PendingNode> next;
    for (std::size_t i = 0; i < level.size(); ++i) {
      std::size_t begin = ranges[level[i].id].begin;
      for (std::size_t c = 0; c < splits[i].centres.size(); ++c) {
        const auto child = static_cast<NodeId>(tree.parents.size());
        tree.parents.push_back(level[i].id);
        tree.centres.push_back(splits[i].centres[c]);
        tree.weights.push_back(0.0);
        const Range child_range{begin, begin + splits[i].sizes[c]};
        ranges.push_back(child_range);
        begin = child_range.end;
        const int child_depth = level[i].depth + 1;
        if (child_depth < options.levels && child_range.size() > 1) {
          next.push_back({child, child_depth});
        } else {
          progress.advance(child_range.size() * (levels - static_cast<std::size_t>(child_depth)));
        }
      }
    }
    level = std::move(next);
  }

  if (options.progress) options.progress({"weighting", 0, 1});
  weighLeaves(tree, ranges, images, image_descriptors.size());
  if (options.progress) options.progress({"weighting", 1, 1});
  return Vocabulary(std::move(tree));
}

}  // namespace edgeslam
