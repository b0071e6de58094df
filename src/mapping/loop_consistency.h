#pragma once
// Temporal consistency of loop candidates: a place-recognition hit is trusted only when the
// candidate's covisibility group keeps being recognised by consecutive keyframes. Each keyframe
// brings candidate groups (a candidate and its covisible keyframes); a group that shares a keyframe
// with a group of the previous keyframe inherits its count plus one, any other starts at zero. A
// candidate is accepted once its count reaches `required` (3: seen by four keyframes in a row).
// Pure bookkeeping over ids, so it can be tested without a map.
#include <cstdint>
#include <vector>

namespace edgeslam {

struct LoopCandidateGroup {
  std::uint64_t candidate = 0;
  std::vector<std::uint64_t> members;  // the candidate and its covisible keyframes, any order
};

class LoopConsistency {
 public:
  explicit LoopConsistency(int required = 3);

  // Feeds one keyframe's candidates (possibly none, which forgets every group); returns the
  // accepted candidates in input order.
  std::vector<std::uint64_t> update(const std::vector<LoopCandidateGroup>& candidates);
  void reset() { groups_.clear(); }

  int required() const { return required_; }
  // The groups carried to the next keyframe, with their counts (for tests and logs).
  struct TrackedGroup {
    std::vector<std::uint64_t> members;  // sorted
    int count = 0;
  };
  const std::vector<TrackedGroup>& groups() const { return groups_; }

 private:
  int required_;
  std::vector<TrackedGroup> groups_;
};

}  // namespace edgeslam
