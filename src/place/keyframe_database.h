#pragma once
// The inverted index for place recognition: for every word, the images (keyframes) that contain
// it with their weight. Loop closing and relocalisation ask it which stored images look like a
// query image. Thread-safe: the mapper adds and erases while the tracker queries.
#include <cstdint>
#include <optional>
#include <unordered_map>
#include <unordered_set>
#include <vector>

#include "place/bow_vector.h"
#include "util/mutex.h"

namespace edgeslam {

using ImageId = std::uint64_t;

struct SharedWordsCandidate {
  ImageId id = 0;
  int shared_words = 0;
};

struct PlaceQueryResult {
  ImageId id = 0;
  double score = 0.0;  // l1Score with the query, in [0, 1]
  int shared_words = 0;
};

class KeyFrameDatabase {
 public:
  // Stores `bow` (normalised to sum 1 if it does not already) under `id`, replacing an earlier
  // vector of the same id.
  void add(ImageId id, const BowVector& bow);
  // No-op for an unknown id.
  void erase(ImageId id);
  void clear();

  std::size_t size() const;
  bool contains(ImageId id) const;
  std::optional<BowVector> bowOf(ImageId id) const;

  // Every stored image sharing at least one word with `query`, with the number of shared words,
  // most shared first (ties by ascending id); ids in `exclude` are left out.
  std::vector<SharedWordsCandidate> candidatesSharingWords(
      const BowVector& query, const std::unordered_set<ImageId>& exclude = {}) const;

  // l1Score between `query` and the stored image; nullopt for an unknown id.
  std::optional<double> score(const BowVector& query, ImageId id) const;

  // Up to `max_results` stored images (0: no limit) with score >= min_score, best first (ties by
  // ascending id); only images sharing a word with the query are considered (others score 0).
  std::vector<PlaceQueryResult> query(const BowVector& query, std::size_t max_results,
                                      double min_score = 0.0,
                                      const std::unordered_set<ImageId>& exclude = {}) const;

 private:
  struct Posting {
    ImageId id;
    double weight;
  };
  struct Accumulator {
    int shared_words = 0;
    // For vectors summing to 1, |a-b|_1 = 2 + sum over shared words of (|a-b| - a - b).
    double shared_term = 0.0;
  };

  void eraseLocked(ImageId id) REQUIRES(mutex_);
  std::unordered_map<ImageId, Accumulator> accumulate(
      const BowVector& query, const std::unordered_set<ImageId>& exclude) const
      REQUIRES_SHARED(mutex_);

  mutable SharedMutex mutex_;
  std::vector<std::vector<Posting>> postings_ GUARDED_BY(mutex_);  // by word id
  std::unordered_map<ImageId, BowVector> images_ GUARDED_BY(mutex_);
};

}  // namespace edgeslam
