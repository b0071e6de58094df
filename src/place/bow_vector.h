#pragma once
// Bag-of-words vectors: an image as the weighted set of vocabulary words its descriptors fall in,
// and the L1 similarity between two of them.
#include <cstddef>
#include <cstdint>
#include <vector>

namespace edgeslam {

using WordId = std::uint32_t;

struct BowEntry {
  WordId word = 0;
  double weight = 0.0;

  friend bool operator==(const BowEntry&, const BowEntry&) = default;
};

// Entries sorted by word id, one per word, weights positive; Vocabulary::transform produces them
// L1-normalised (weights sum to 1).
struct BowVector {
  std::vector<BowEntry> entries;

  std::size_t size() const { return entries.size(); }
  bool empty() const { return entries.empty(); }
  auto begin() const { return entries.begin(); }
  auto end() const { return entries.end(); }
  // 0 when the word is absent (binary search).
  double weightOf(WordId word) const;
  double sum() const;

  friend bool operator==(const BowVector&, const BowVector&) = default;
};

// Builds a valid vector from unordered (word, weight) pairs: sorts, adds up repeated words and
// drops non-positive weights.
BowVector makeBowVector(std::vector<BowEntry> entries);

// Scales the weights to sum 1 (no-op for an empty vector).
void normalizeL1(BowVector& bow);

// 1 - 0.5 * |a - b|_1 for L1-normalised vectors: 1 for the same vector, 0 when no word is shared.
// Clamped to [0, 1] against rounding.
double l1Score(const BowVector& a, const BowVector& b);

// Number of words present in both.
int sharedWordCount(const BowVector& a, const BowVector& b);

}  // namespace edgeslam
