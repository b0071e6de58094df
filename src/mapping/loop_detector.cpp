#include "mapping/loop_detector.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <unordered_set>

namespace edgeslam {

LoopDetector::LoopDetector(std::shared_ptr<const Vocabulary> vocabulary,
                           LoopDetectorOptions options)
    : vocabulary_(std::move(vocabulary)), options_(options) {
  if (vocabulary_ == nullptr || vocabulary_->empty()) {
    throw std::invalid_argument("LoopDetector: a non-empty vocabulary is required");
  }
}

const KeyFrameBow& LoopDetector::describe(const KeyFrame& keyframe) {
  {
    MutexLock lock(bow_mutex_);
    if (const auto it = bows_.find(keyframe.id()); it != bows_.end()) return it->second;
  }
  KeyFrameBow bow;
  if (const auto place = keyframe.place();
      place != nullptr && place->vocabulary == vocabulary_.get() &&
      place->direct_index_depth == options_.direct_index_depth) {
    bow.bow = place->bow;  // local mapping described it already
    bow.features = place->features;
  } else {
    const int levels_up = std::max(0, vocabulary_->levels() - options_.direct_index_depth);
    vocabulary_->transform(keyframe.features().descriptors, levels_up, bow.bow, bow.features);
  }
  MutexLock lock(bow_mutex_);
  return bows_.try_emplace(keyframe.id(), std::move(bow)).first->second;
}

const KeyFrameBow* LoopDetector::bowOf(KeyFrameId id) const {
  MutexLock lock(bow_mutex_);
  const auto it = bows_.find(id);
  return it == bows_.end() ? nullptr : &it->second;
}

void LoopDetector::clear() {
  MutexLock lock(bow_mutex_);
  bows_.clear();
  database_.clear();
  consistency_.clear();
}

std::size_t LoopDetector::forgetIf(const std::function<bool(KeyFrameId)>& gone) {
  MutexLock lock(bow_mutex_);
  std::size_t forgotten = 0;
  for (auto it = bows_.begin(); it != bows_.end();) {
    if (gone(it->first)) {
      database_.erase(it->first);
      it = bows_.erase(it);
      ++forgotten;
    } else {
      ++it;
    }
  }
  return forgotten;
}

std::size_t LoopDetector::describedCount() const {
  MutexLock lock(bow_mutex_);
  return bows_.size();
}

LoopDetection LoopDetector::detect(KeyFrame* keyframe, const Map& map, bool search, bool store) {
  const KeyFrameBow* own = bowOf(keyframe->id());
  if (own == nullptr) {
    throw std::logic_error("LoopDetector::detect: keyframe " + std::to_string(keyframe->id()) +
                           " was not described");
  }
  LoopDetection out;
  if (search) {
    // The least similar covisible keyframe sets the bar: a true revisit should look at least as
    // much like the current image as the keyframes it shares points with.
    std::unordered_set<ImageId> connected{keyframe->id()};
    double min_score = 1.0;
    bool scored = false;
    const std::size_t gap = options_.connected_older_than_frames;
    for (const auto& [kf, weight] : keyframe->connections()) {
      if (gap == 0 || kf->frameIndex() + gap > keyframe->frameIndex()) connected.insert(kf->id());
      if (kf->isBad()) continue;
      if (const KeyFrameBow* other = bowOf(kf->id())) {
        min_score = std::min(min_score, l1Score(own->bow, other->bow));
        scored = true;
      }
    }
    std::vector<PlaceQueryResult> hits;
    if (scored) {
      out.min_score = min_score;
      const auto sharing = database_.candidatesSharingWords(own->bow, connected);
      if (!sharing.empty()) {
        const int min_shared = static_cast<int>(
            std::ceil(options_.min_shared_words_ratio * sharing.front().shared_words));
        for (const PlaceQueryResult& hit : database_.query(own->bow, 0, min_score, connected)) {
          if (hit.shared_words < min_shared) continue;
          const KeyFrame* kf = map.keyFrame(hit.id);
          if (kf == nullptr || kf->isBad()) {
            database_.erase(hit.id);  // culled since it was filed
            continue;
          }
          hits.push_back(hit);
        }
      }
    }
    out.raw_candidates = hits.size();
    std::vector<LoopCandidateGroup> groups;
    for (KeyFrame* candidate : groupCandidates(keyframe, map, hits)) {
      LoopCandidateGroup group{candidate->id(), {}};
      for (const auto& [kf, weight] : candidate->connections()) group.members.push_back(kf->id());
      groups.push_back(std::move(group));
    }
    LoopConsistency& consistency =
        consistency_.try_emplace(idOrigin(keyframe->id()), options_.consistency_required)
            .first->second;
    for (const std::uint64_t id : consistency.update(groups)) {
      if (KeyFrame* kf = map.keyFrame(id); kf != nullptr && !kf->isBad()) {
        out.candidates.push_back(kf);
      }
    }
  }
  if (store) database_.add(keyframe->id(), own->bow);
  return out;
}

std::vector<KeyFrame*> LoopDetector::groupCandidates(
    KeyFrame* keyframe, const Map& map, const std::vector<PlaceQueryResult>& hits) const {
  std::unordered_map<ImageId, double> score_of;
  for (const PlaceQueryResult& hit : hits) score_of.emplace(hit.id, hit.score);

  // A single lucky image is weaker evidence than a neighbourhood of similar ones: each hit
  // collects the scores of its best covisible keyframes that are hits too, and the group is
  // represented by its best-scoring member.
  struct Group {
    KeyFrame* best;
    double total;
  };
  std::vector<Group> groups;
  double best_total = 0.0;
  for (const PlaceQueryResult& hit : hits) {
    KeyFrame* candidate = map.keyFrame(hit.id);
    if (candidate == nullptr || candidate == keyframe) continue;
    Group group{candidate, hit.score};
    double best_score = hit.score;
    for (KeyFrame* neighbour : candidate->bestCovisibles(options_.group_neighbours)) {
      const auto it = score_of.find(neighbour->id());
      if (it == score_of.end() || neighbour->isBad()) continue;
      group.total += it->second;
      if (it->second > best_score) {
        best_score = it->second;
        group.best = neighbour;
      }
    }
    best_total = std::max(best_total, group.total);
    groups.push_back(group);
  }
  std::stable_sort(groups.begin(), groups.end(),
                   [](const Group& a, const Group& b) { return a.total > b.total; });
  std::vector<KeyFrame*> out;
  for (const Group& group : groups) {
    if (group.total < options_.min_group_score_ratio * best_total) break;
    if (std::find(out.begin(), out.end(), group.best) == out.end()) out.push_back(group.best);
  }
  return out;
}

}  // namespace edgeslam
