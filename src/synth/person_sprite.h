#pragma once
// People cut out of real photos by the project's segmenter: colour plus a binary silhouette,
// cropped to the person, ready to be scaled and pasted over other images.
#include <filesystem>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "semantic/segmentation.h"
#include "semantic/segmenter.h"

namespace edgeslam {

struct PersonSprite {
  cv::Mat3b color;       // BGR, cropped to the silhouette's bounding box
  cv::Mat1f silhouette;  // same size, 1 inside the person, 0 outside (hard; feathered when drawn)
  std::string photo;     // file name of the source photo
  cv::Rect box;          // the silhouette's box in the source photo
  float score = 0.0f;    // detection score
};

struct SpriteOptions {
  int min_height_px = 150;  // smaller people are too blurry when scaled up
  // People whose silhouette comes closer to the border than this share of the photo's smaller
  // side are taken as cut by it (half bodies, as in close-ups).
  double border_margin = 0.015;
  // Wider silhouettes (width / height) are not one standing person: close-ups, groups, masks
  // leaking onto a neighbour.
  double max_aspect = 0.6;
  double min_fill = 0.15;       // silhouette area / box area below this: a broken mask
  double edge_shave = 0.004;    // of the height: eroded off the mask's rim (photo background)
  int max_sprite_height = 800;  // larger cut-outs are shrunk (INTER_AREA) to save work later
};

// The photo's persons with a pixel mask (not box-only), tall enough, shaped like one standing
// person (not wider than max_aspect) and not cut by the border.
// Keeps the largest connected part of each mask (masks sometimes leak onto a neighbour).
std::vector<PersonSprite> extractPersonSprites(const cv::Mat3b& photo,
                                               const Segmentation& segmentation,
                                               const std::string& photo_name,
                                               const SpriteOptions& options = {});

// Segments every .jpg/.jpeg/.png in `folder` (sorted by name) and gathers their sprites.
// Throws std::runtime_error naming the folder when it is missing, holds no image, or yields no
// usable person.
std::vector<PersonSprite> loadPeopleSprites(const std::filesystem::path& folder,
                                            Segmenter& segmenter,
                                            const SpriteOptions& options = {});

// `datasets/people` beside the segmenter's default model folder ($EDGESLAM_SHARED or the build's
// shared folder).
std::filesystem::path defaultPeopleDirectory();

}  // namespace edgeslam
