#include "relocalize/keyframe_places.h"

#include <algorithm>
#include <stdexcept>

#include "place/bow_matching.h"

namespace edgeslam {
namespace {

// The direct index files features two levels above the leaves: ~100 features per node pair.
constexpr int kDirectIndexLevelsUp = 2;

}  // namespace

KeyFramePlaces::KeyFramePlaces(std::shared_ptr<const Vocabulary> vocabulary)
    : vocabulary_(std::move(vocabulary)) {
  if (!vocabulary_ || vocabulary_->empty()) {
    throw std::invalid_argument("place recognition needs a non-empty vocabulary");
  }
}

KeyFramePlaces::Indexed KeyFramePlaces::index(const FrameFeatures& features) const {
  Indexed out;
  vocabulary_->transform(features.descriptors, kDirectIndexLevelsUp, out.bow, out.direct);
  return out;
}

std::shared_ptr<const KeyFramePlace> KeyFramePlaces::add(const KeyFrame& keyframe) {
  Indexed indexed = index(keyframe.features());
  database_.add(keyframe.id(), indexed.bow);
  auto place = std::make_shared<KeyFramePlace>();
  place->bow = std::move(indexed.bow);
  place->features = std::move(indexed.direct);
  place->direct_index_depth = std::max(0, vocabulary_->levels() - kDirectIndexLevelsUp);
  place->vocabulary = vocabulary_.get();
  places_[keyframe.id()] = place;
  return place;
}

std::shared_ptr<const KeyFramePlace> KeyFramePlaces::addDescribed(const KeyFrame& keyframe) {
  const std::shared_ptr<const KeyFramePlace> described = keyframe.place();
  if (described == nullptr || described->vocabulary != vocabulary_.get() ||
      described->direct_index_depth != std::max(0, vocabulary_->levels() - kDirectIndexLevelsUp)) {
    return add(keyframe);
  }
  database_.add(keyframe.id(), described->bow);
  places_[keyframe.id()] = described;
  return described;
}

std::size_t KeyFramePlaces::forgetIf(const std::function<bool(KeyFrameId)>& gone) {
  std::vector<KeyFrameId> forgotten;
  for (const auto& [id, place] : places_) {
    if (gone(id)) forgotten.push_back(id);
  }
  for (KeyFrameId id : forgotten) erase(id);
  return forgotten.size();
}

void KeyFramePlaces::erase(KeyFrameId id) {
  database_.erase(id);
  places_.erase(id);
}

void KeyFramePlaces::clear() {
  database_.clear();
  places_.clear();
  query_features_ = nullptr;
}

std::vector<KeyFrameId> KeyFramePlaces::similar(const FrameFeatures& frame, std::size_t max_results,
                                                double relative_min) {
  query_ = index(frame);
  query_features_ = &frame;
  const std::vector<PlaceQueryResult> results = database_.query(query_.bow, max_results);
  std::vector<KeyFrameId> out;
  if (results.empty()) return out;
  const double best = results.front().score;
  for (const PlaceQueryResult& r : results) {
    if (r.score >= relative_min * best) out.push_back(r.id);
  }
  return out;
}

std::vector<cv::DMatch> KeyFramePlaces::match(const KeyFrame& keyframe) const {
  const auto it = places_.find(keyframe.id());
  if (it == places_.end() || query_features_ == nullptr) return {};
  const FrameFeatures& frame = *query_features_;
  const FrameFeatures& kf = keyframe.features();
  return matchByBow(query_.direct, frame.keypoints, frame.descriptors, it->second->features,
                    kf.keypoints, kf.descriptors);
}

}  // namespace edgeslam
