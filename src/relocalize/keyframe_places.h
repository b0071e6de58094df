#pragma once
// The client's place recognition: every keyframe it makes goes into a bag-of-words database, so
// that a lost frame can find the keyframes that look like it (relocalisation), and be matched to
// them word by word.
#include <functional>
#include <memory>
#include <unordered_map>
#include <vector>

#include "map/frame.h"
#include "map/keyframe.h"
#include "place/feature_vector.h"
#include "place/keyframe_database.h"
#include "place/vocabulary.h"

namespace edgeslam {

class KeyFramePlaces {
 public:
  explicit KeyFramePlaces(std::shared_ptr<const Vocabulary> vocabulary);

  // Returns the keyframe's description (bag of words and direct index), which the caller may
  // attach to the keyframe (KeyFrame::setPlace) for bag-of-words triangulation.
  std::shared_ptr<const KeyFramePlace> add(const KeyFrame& keyframe);
  // As add(), but a keyframe already described with this vocabulary at this direct-index depth (a
  // stored map's bags of words) is filed with its description instead of being described again.
  std::shared_ptr<const KeyFramePlace> addDescribed(const KeyFrame& keyframe);
  // A keyframe the client no longer holds (evicted from its bounded map); no-op when unknown.
  void erase(KeyFrameId id);
  void clear();
  // Forgets every keyframe `gone` says the map no longer has; returns how many.
  std::size_t forgetIf(const std::function<bool(KeyFrameId)>& gone);
  std::size_t size() const { return places_.size(); }

  // Indexes a frame to look up, and returns the ids of the stored keyframes most similar to it,
  // best first, at most `max_results`, none scoring under `relative_min` times the best.
  std::vector<KeyFrameId> similar(const FrameFeatures& frame, std::size_t max_results,
                                  double relative_min = 0.6);
  // Matches of the last frame given to similar() (queryIdx) to a keyframe's keypoints (trainIdx)
  // through the direct index, rotation-checked.
  std::vector<cv::DMatch> match(const KeyFrame& keyframe) const;

 private:
  struct Indexed {
    BowVector bow;
    FeatureVector direct;
  };
  Indexed index(const FrameFeatures& features) const;

  std::shared_ptr<const Vocabulary> vocabulary_;
  KeyFrameDatabase database_;
  // Each keyframe's description, shared with the keyframe where the tracker attaches it.
  std::unordered_map<KeyFrameId, std::shared_ptr<const KeyFramePlace>> places_;
  // The frame being looked up, indexed once for all its candidates.
  const FrameFeatures* query_features_ = nullptr;
  Indexed query_;
};

}  // namespace edgeslam
