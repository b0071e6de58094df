#include "mapping/loop_consistency.h"

#include <algorithm>
#include <stdexcept>
#include <string>

namespace edgeslam {
namespace {

bool intersects(const std::vector<std::uint64_t>& a, const std::vector<std::uint64_t>& b) {
  auto i = a.begin();
  auto j = b.begin();
  while (i != a.end() && j != b.end()) {
    if (*i == *j) return true;
    if (*i < *j) {
      ++i;
    } else {
      ++j;
    }
  }
  return false;
}

}  // namespace

LoopConsistency::LoopConsistency(int required) : required_(required) {
  if (required < 0) {
    throw std::invalid_argument("LoopConsistency: required count must be >= 0, got " +
                                std::to_string(required));
  }
}

std::vector<std::uint64_t> LoopConsistency::update(
    const std::vector<LoopCandidateGroup>& candidates) {
  std::vector<TrackedGroup> next;
  std::vector<std::uint64_t> accepted;
  // A previous group carries on into at most one new group, so one lucky overlap cannot fan out.
  std::vector<bool> continued(groups_.size(), false);
  for (const LoopCandidateGroup& candidate : candidates) {
    std::vector<std::uint64_t> members = candidate.members;
    members.push_back(candidate.candidate);
    std::sort(members.begin(), members.end());
    members.erase(std::unique(members.begin(), members.end()), members.end());

    bool consistent = false;
    bool is_accepted = false;
    for (std::size_t g = 0; g < groups_.size(); ++g) {
      if (!intersects(members, groups_[g].members)) continue;
      consistent = true;
      const int count = groups_[g].count + 1;
      if (!continued[g]) {
        next.push_back({members, count});
        continued[g] = true;
      }
      if (count >= required_ && !is_accepted) {
        accepted.push_back(candidate.candidate);
        is_accepted = true;
      }
    }
    if (!consistent) {
      next.push_back({members, 0});
      if (required_ == 0) accepted.push_back(candidate.candidate);
    }
  }
  groups_ = std::move(next);
  return accepted;
}

}  // namespace edgeslam
