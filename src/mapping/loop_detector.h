#pragma once
// Loop candidates from bag-of-words place recognition: every mapped keyframe is described by its
// bag of words (kept here by keyframe id, with the direct index for matching) and filed in an
// inverted-index database. A keyframe's candidates are the stored keyframes that are not connected
// to it in the covisibility graph yet look at least as similar to it as its least similar
// covisible keyframe does; hits are pooled by covisibility group and must be temporally
// consistent (loop_consistency.h) before they are handed on to geometric verification.
#include <cstddef>
#include <functional>
#include <map>
#include <memory>
#include <unordered_map>
#include <vector>

#include "map/keyframe.h"
#include "map/map.h"
#include "mapping/loop_consistency.h"
#include "place/bow_vector.h"
#include "place/feature_vector.h"
#include "place/keyframe_database.h"
#include "place/vocabulary.h"
#include "util/mutex.h"

namespace edgeslam {

struct LoopDetectorOptions {
  int consistency_required = 3;
  // Direct-index depth for BoW matching: features are filed under their ancestor at this depth of
  // the tree (2: k^2 nodes, as DBoW2-based systems use; the leaves when the tree is shallower).
  int direct_index_depth = 2;
  // Candidates must share at least this fraction of the best candidate's shared words.
  double min_shared_words_ratio = 0.8;
  // Covisibility groups scoring below this fraction of the best group are dropped.
  double min_group_score_ratio = 0.75;
  std::size_t group_neighbours = 10;
  // Tests only: also consider keyframes already connected to the query when they are at least
  // this many frames older (0 = never; the normal rule excludes every connected keyframe).
  std::size_t connected_older_than_frames = 0;
};

struct KeyFrameBow {
  BowVector bow;
  FeatureVector features;
};

struct LoopDetection {
  std::vector<KeyFrame*> candidates;  // consistent candidates, best group first
  double min_score = 0.0;             // the covisible-keyframe score the candidates had to beat
  std::size_t raw_candidates = 0;     // database hits before grouping and consistency
};

class LoopDetector {
 public:
  LoopDetector(std::shared_ptr<const Vocabulary> vocabulary, LoopDetectorOptions options = {});

  // Computes and keeps the keyframe's bag of words (features are immutable: no lock needed).
  const KeyFrameBow& describe(const KeyFrame& keyframe);
  // nullptr when the keyframe was never described.
  const KeyFrameBow* bowOf(KeyFrameId id) const;

  // The caller holds the map's update mutex. The keyframe must have been described. Runs the
  // candidate search and the consistency update, then (unless `store` is false) files the keyframe
  // in the database.
  LoopDetection detect(KeyFrame* keyframe, const Map& map, bool search = true, bool store = true)
      REQUIRES(map.updateMutex());

  // Forgets the consistency history (after a loop has been closed or the map reset).
  void resetConsistency() { consistency_.clear(); }
  // Drops everything (map reset).
  void clear();
  // Forgets the keyframes `gone` says the map no longer has: their bags of words and database
  // entries. Returns how many.
  std::size_t forgetIf(const std::function<bool(KeyFrameId)>& gone);
  std::size_t describedCount() const;
  std::size_t databaseSize() const { return database_.size(); }
  const LoopDetectorOptions& options() const { return options_; }

 private:
  std::vector<KeyFrame*> groupCandidates(KeyFrame* keyframe, const Map& map,
                                         const std::vector<PlaceQueryResult>& hits) const
      REQUIRES(map.updateMutex());

  std::shared_ptr<const Vocabulary> vocabulary_;
  LoopDetectorOptions options_;
  mutable Mutex bow_mutex_;
  std::unordered_map<KeyFrameId, KeyFrameBow> bows_ GUARDED_BY(bow_mutex_);
  KeyFrameDatabase database_;
  // One history per client (by the keyframes' id origin): consistency is over one camera's
  // consecutive keyframes, and several clients' keyframes come interleaved into one map.
  std::map<std::uint8_t, LoopConsistency> consistency_;
};

}  // namespace edgeslam
