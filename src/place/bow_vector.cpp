#include "place/bow_vector.h"

#include <algorithm>
#include <cmath>

namespace edgeslam {

double BowVector::weightOf(WordId word) const {
  const auto it = std::lower_bound(entries.begin(), entries.end(), word,
                                   [](const BowEntry& e, WordId w) { return e.word < w; });
  return it != entries.end() && it->word == word ? it->weight : 0.0;
}

double BowVector::sum() const {
  double total = 0.0;
  for (const BowEntry& e : entries) total += e.weight;
  return total;
}

BowVector makeBowVector(std::vector<BowEntry> entries) {
  std::sort(entries.begin(), entries.end(),
            [](const BowEntry& a, const BowEntry& b) { return a.word < b.word; });
  BowVector bow;
  bow.entries.reserve(entries.size());
  for (const BowEntry& e : entries) {
    if (!bow.entries.empty() && bow.entries.back().word == e.word) {
      bow.entries.back().weight += e.weight;
    } else {
      bow.entries.push_back(e);
    }
  }
  std::erase_if(bow.entries, [](const BowEntry& e) { return !(e.weight > 0.0); });
  return bow;
}

void normalizeL1(BowVector& bow) {
  const double total = bow.sum();
  if (total <= 0.0) return;
  for (BowEntry& e : bow.entries) e.weight /= total;
}

double l1Score(const BowVector& a, const BowVector& b) {
  double distance = 0.0;
  auto ia = a.entries.begin();
  auto ib = b.entries.begin();
  while (ia != a.entries.end() || ib != b.entries.end()) {
    if (ib == b.entries.end() || (ia != a.entries.end() && ia->word < ib->word)) {
      distance += ia->weight;
      ++ia;
    } else if (ia == a.entries.end() || ib->word < ia->word) {
      distance += ib->weight;
      ++ib;
    } else {
      distance += std::abs(ia->weight - ib->weight);
      ++ia;
      ++ib;
    }
  }
  return std::clamp(1.0 - 0.5 * distance, 0.0, 1.0);
}

int sharedWordCount(const BowVector& a, const BowVector& b) {
  int count = 0;
  auto ia = a.entries.begin();
  auto ib = b.entries.begin();
  while (ia != a.entries.end() && ib != b.entries.end()) {
    if (ia->word < ib->word) {
      ++ia;
    } else if (ib->word < ia->word) {
      ++ib;
    } else {
      ++count;
      ++ia;
      ++ib;
    }
  }
  return count;
}

}  // namespace edgeslam
