#pragma once
// The shared people photos segmented once per test binary (each segmentation costs ~0.15 s).
#include <map>
#include <memory>
#include <opencv2/imgcodecs.hpp>
#include <string>

#include "semantic/segmenter.h"
#include "support/shared_data.h"

namespace edgeslam::test {

struct SegmentedPhoto {
  cv::Mat image;
  Segmentation segmentation;
};

inline Segmenter& sharedSegmenter() {
  static const std::unique_ptr<Segmenter> segmenter = [] {
    SegmenterOptions options;
    options.model_dir = sharedPath("models");
    return makeSegmenter(options);
  }();
  return *segmenter;
}

// `name` inside datasets/people; the caller checks that the file exists first.
inline const SegmentedPhoto& segmentedPhoto(const std::string& name) {
  static std::map<std::string, SegmentedPhoto> cache;
  auto it = cache.find(name);
  if (it == cache.end()) {
    SegmentedPhoto photo;
    photo.image = cv::imread(sharedPath("datasets/people/" + name).string(), cv::IMREAD_COLOR);
    photo.segmentation = sharedSegmenter().segment(photo.image);
    it = cache.emplace(name, std::move(photo)).first;
  }
  return it->second;
}

}  // namespace edgeslam::test
