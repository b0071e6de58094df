#include "synth/person_sprite.h"

#include <fmt/format.h>

#include <algorithm>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

namespace edgeslam {
namespace {

namespace fs = std::filesystem;

constexpr int kPersonClass = 0;

cv::Mat1b largestComponent(const cv::Mat1b& mask) {
  cv::Mat1i labels;
  cv::Mat stats, centroids;
  const int count = cv::connectedComponentsWithStats(mask, labels, stats, centroids, 8);
  int best = 0;
  int best_area = 0;
  for (int label = 1; label < count; ++label) {
    const int area = stats.at<int>(label, cv::CC_STAT_AREA);
    if (area > best_area) best = label, best_area = area;
  }
  cv::Mat1b component = labels == best;
  if (best == 0) component.setTo(0);
  return component;
}

bool touchesBorder(const cv::Rect& box, cv::Size size, int margin) {
  return box.x < margin || box.y < margin || box.br().x > size.width - margin ||
         box.br().y > size.height - margin;
}

bool isPhoto(const fs::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext == ".jpg" || ext == ".jpeg" || ext == ".png";
}

}  // namespace

std::vector<PersonSprite> extractPersonSprites(const cv::Mat3b& photo,
                                               const Segmentation& segmentation,
                                               const std::string& photo_name,
                                               const SpriteOptions& options) {
  std::vector<PersonSprite> sprites;
  for (const SegmentedInstance& instance : segmentation.instances) {
    if (instance.class_id != kPersonClass || instance.mask_is_box || instance.mask.empty()) {
      continue;
    }
    cv::Mat1b silhouette = largestComponent(instance.mask > 0);
    const cv::Rect box = cv::boundingRect(silhouette);
    const int margin = std::max(
        2, static_cast<int>(std::lround(options.border_margin * std::min(photo.rows, photo.cols))));
    if (box.height < options.min_height_px || touchesBorder(box, photo.size(), margin) ||
        box.width > options.max_aspect * box.height) {
      continue;
    }
    const double fill =
        static_cast<double>(cv::countNonZero(silhouette(box))) / static_cast<double>(box.area());
    if (fill < options.min_fill) continue;

    // Masks tend to take a thin rim of the photo's background: shave it off.
    const int shave = std::max(1, static_cast<int>(std::lround(options.edge_shave * box.height)));
    cv::erode(silhouette, silhouette,
              cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(2 * shave + 1, 2 * shave + 1)));

    PersonSprite sprite;
    sprite.photo = photo_name;
    sprite.box = box;
    sprite.score = instance.score;
    photo(box).copyTo(sprite.color);
    silhouette(box).convertTo(sprite.silhouette, CV_32F, 1.0 / 255.0);
    if (box.height > options.max_sprite_height) {
      const double scale = static_cast<double>(options.max_sprite_height) / box.height;
      const cv::Size size(std::max(1, static_cast<int>(std::lround(box.width * scale))),
                          options.max_sprite_height);
      cv::resize(sprite.color, sprite.color, size, 0, 0, cv::INTER_AREA);
      cv::resize(sprite.silhouette, sprite.silhouette, size, 0, 0, cv::INTER_AREA);
      sprite.silhouette = sprite.silhouette > 0.5f;
      sprite.silhouette.convertTo(sprite.silhouette, CV_32F, 1.0 / 255.0);
    }
    sprites.push_back(std::move(sprite));
  }
  return sprites;
}

std::vector<PersonSprite> loadPeopleSprites(const fs::path& folder, Segmenter& segmenter,
                                            const SpriteOptions& options) {
  if (!fs::is_directory(folder)) {
    throw std::runtime_error(fmt::format("people folder not found: {}", folder.string()));
  }
  std::vector<fs::path> photos;
  for (const auto& entry : fs::directory_iterator(folder)) {
    if (entry.is_regular_file() && isPhoto(entry.path())) photos.push_back(entry.path());
  }
  std::sort(photos.begin(), photos.end());
  if (photos.empty()) {
    throw std::runtime_error(
        fmt::format("{}: no .jpg/.jpeg/.png photo of people in it", folder.string()));
  }
  std::vector<PersonSprite> sprites;
  for (const fs::path& path : photos) {
    const cv::Mat image = cv::imread(path.string(), cv::IMREAD_COLOR);
    if (image.empty()) throw std::runtime_error(fmt::format("cannot decode {}", path.string()));
    const cv::Mat3b photo = image;
    auto found =
        extractPersonSprites(photo, segmenter.segment(photo), path.filename().string(), options);
    for (auto& sprite : found) sprites.push_back(std::move(sprite));
  }
  if (sprites.empty()) {
    throw std::runtime_error(fmt::format(
        "{}: the segmenter found no whole standing person (pixel mask, >= {} px tall, not cut by "
        "the border) in its {} photo(s)",
        folder.string(), options.min_height_px, photos.size()));
  }
  return sprites;
}

fs::path defaultPeopleDirectory() {
  return defaultModelDirectory().parent_path() / "datasets" / "people";
}

}  // namespace edgeslam
