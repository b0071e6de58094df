#include "place/keyframe_database.h"

#include <algorithm>
#include <cmath>
#include <mutex>

namespace edgeslam {
namespace {

// Normalised copy; weights that already sum to 1 are kept bit-for-bit.
BowVector normalised(const BowVector& bow) {
  BowVector copy = bow;
  if (std::abs(copy.sum() - 1.0) > 1e-9) normalizeL1(copy);
  return copy;
}

}  // namespace

void KeyFrameDatabase::add(ImageId id, const BowVector& bow) {
  BowVector stored = normalised(bow);
  const WriterLock lock(mutex_);
  eraseLocked(id);
  for (const BowEntry& e : stored) {
    if (e.word >= postings_.size()) postings_.resize(static_cast<std::size_t>(e.word) + 1);
    postings_[e.word].push_back({id, e.weight});
  }
  images_.emplace(id, std::move(stored));
}

void KeyFrameDatabase::erase(ImageId id) {
  const WriterLock lock(mutex_);
  eraseLocked(id);
}

void KeyFrameDatabase::eraseLocked(ImageId id) {
  const auto it = images_.find(id);
  if (it == images_.end()) return;
  for (const BowEntry& e : it->second) {
    std::erase_if(postings_[e.word], [id](const Posting& p) { return p.id == id; });
  }
  images_.erase(it);
}

void KeyFrameDatabase::clear() {
  const WriterLock lock(mutex_);
  postings_.clear();
  images_.clear();
}

std::size_t KeyFrameDatabase::size() const {
  const ReaderLock lock(mutex_);
  return images_.size();
}

bool KeyFrameDatabase::contains(ImageId id) const {
  const ReaderLock lock(mutex_);
  return images_.contains(id);
}

std::optional<BowVector> KeyFrameDatabase::bowOf(ImageId id) const {
  const ReaderLock lock(mutex_);
  const auto it = images_.find(id);
  if (it == images_.end()) return std::nullopt;
  return it->second;
}

// Walks the query's words once; the shared-word terms of l1Score add up per image.
std::unordered_map<ImageId, KeyFrameDatabase::Accumulator> KeyFrameDatabase::accumulate(
    const BowVector& query, const std::unordered_set<ImageId>& exclude) const {
  std::unordered_map<ImageId, Accumulator> found;
  for (const BowEntry& q : query) {
    if (q.word >= postings_.size()) continue;
    for (const Posting& p : postings_[q.word]) {
      if (exclude.contains(p.id)) continue;
      Accumulator& a = found[p.id];
      ++a.shared_words;
      a.shared_term += std::abs(q.weight - p.weight) - q.weight - p.weight;
    }
  }
  return found;
}

std::vector<SharedWordsCandidate> KeyFrameDatabase::candidatesSharingWords(
    const BowVector& query, const std::unordered_set<ImageId>& exclude) const {
  std::vector<SharedWordsCandidate> candidates;
  {
    const ReaderLock lock(mutex_);
    for (const auto& [id, a] : accumulate(normalised(query), exclude)) {
      candidates.push_back({id, a.shared_words});
    }
  }
  std::sort(candidates.begin(), candidates.end(), [](const auto& a, const auto& b) {
    return a.shared_words != b.shared_words ? a.shared_words > b.shared_words : a.id < b.id;
  });
  return candidates;
}

std::optional<double> KeyFrameDatabase::score(const BowVector& query, ImageId id) const {
  const ReaderLock lock(mutex_);
  const auto it = images_.find(id);
  if (it == images_.end()) return std::nullopt;
  return l1Score(normalised(query), it->second);
}

std::vector<PlaceQueryResult> KeyFrameDatabase::query(
    const BowVector& query, std::size_t max_results, double min_score,
    const std::unordered_set<ImageId>& exclude) const {
  std::vector<PlaceQueryResult> results;
  {
    const ReaderLock lock(mutex_);
    for (const auto& [id, a] : accumulate(normalised(query), exclude)) {
      const double s = std::clamp(-0.5 * a.shared_term, 0.0, 1.0);
      if (s >= min_score) results.push_back({id, s, a.shared_words});
    }
  }
  std::sort(results.begin(), results.end(), [](const auto& a, const auto& b) {
    return a.score != b.score ? a.score > b.score : a.id < b.id;
  });
  if (max_results > 0 && results.size() > max_results) results.resize(max_results);
  return results;
}

}  // namespace edgeslam
