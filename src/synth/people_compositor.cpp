#include "synth/people_compositor.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

namespace edgeslam {
namespace {

// With three people at most, a pixel whose combined alpha exceeds 0.5 has one person whose own
// alpha exceeds 1 - 0.5^(1/3) ~ 0.206.
constexpr float kDepthAlpha = 0.2f;

struct PersonLayer {
  cv::Rect target;
  cv::Mat1f alpha;
  double depth_m;
};

int featherRadius(const CompositeOptions& options) {
  return static_cast<int>(std::ceil(3.0 * options.feather_sigma_px));
}

// A sprite scaled to its placement, with a feathered alpha, and where it lands in the image.
struct ScaledSprite {
  cv::Mat color;  // same channel count as the target image (may be empty)
  cv::Mat1f alpha;
  cv::Point origin;  // image position of alpha(0, 0)
};

ScaledSprite scaleSprite(const PersonSprite& sprite, const PersonPlacement& placement, int channels,
                         const CompositeOptions& options) {
  const double scale = placement.height_px / sprite.silhouette.rows;
  const cv::Size size(std::max(1, static_cast<int>(std::lround(sprite.silhouette.cols * scale))),
                      std::max(1, static_cast<int>(std::lround(placement.height_px))));
  const int interpolation = scale < 1.0 ? cv::INTER_AREA : cv::INTER_LINEAR;
  const int pad = featherRadius(options);

  ScaledSprite scaled;
  cv::Mat1f silhouette;
  cv::resize(sprite.silhouette, silhouette, size, 0, 0, interpolation);
  cv::copyMakeBorder(silhouette, scaled.alpha, pad, pad, pad, pad, cv::BORDER_CONSTANT, 0);
  if (options.feather_sigma_px > 0.0) {
    cv::GaussianBlur(scaled.alpha, scaled.alpha, cv::Size(2 * pad + 1, 2 * pad + 1),
                     options.feather_sigma_px);
  }
  if (channels > 0) {
    cv::Mat color;
    cv::resize(sprite.color, color, size, 0, 0, interpolation);
    if (channels == 1) cv::cvtColor(color, color, cv::COLOR_BGR2GRAY);
    cv::copyMakeBorder(color, scaled.color, pad, pad, pad, pad, cv::BORDER_REPLICATE);
  }
  if (placement.mirrored) {
    cv::flip(scaled.alpha, scaled.alpha, 1);
    if (!scaled.color.empty()) cv::flip(scaled.color, scaled.color, 1);
  }
  scaled.origin =
      cv::Point(static_cast<int>(std::lround(placement.center_x - 0.5 * size.width)) - pad,
                static_cast<int>(std::lround(placement.foot_y - placement.height_px)) - pad);
  return scaled;
}

// Faint parts of `alpha` farther than `radius` from where it exceeds 0.5 (thin hair or straps,
// a feather reaching in from a body outside the image) are dropped, so that the image changes
// only near the ground-truth mask.
void keepNearMask(cv::Mat1f& alpha, int radius) {
  cv::Mat1b near_mask;
  cv::dilate(alpha > 0.5f, near_mask,
             cv::getStructuringElement(cv::MORPH_RECT, cv::Size(2 * radius + 1, 2 * radius + 1)));
  alpha.setTo(0.0f, near_mask == 0);
}

template <typename Pixel>
void blend(cv::Mat& image_roi, const cv::Mat& color, const cv::Mat1f& alpha) {
  constexpr int kChannels = cv::DataType<Pixel>::channels;
  for (int y = 0; y < image_roi.rows; ++y) {
    auto* out = image_roi.ptr<Pixel>(y);
    const auto* in = color.ptr<Pixel>(y);
    const float* a = alpha.ptr<float>(y);
    for (int x = 0; x < image_roi.cols; ++x) {
      if (a[x] <= 0.0f) continue;
      const float w = std::min(a[x], 1.0f);
      if constexpr (kChannels == 1) {
        out[x] = cv::saturate_cast<uchar>((1.0f - w) * out[x] + w * in[x]);
      } else {
        for (int c = 0; c < kChannels; ++c) {
          out[x][c] = cv::saturate_cast<uchar>((1.0f - w) * out[x][c] + w * in[x][c]);
        }
      }
    }
  }
}

// Percentile of the positive values of `values` where `mask` is set; 0 when there are none.
float positivePercentile(const cv::Mat1f& values, const cv::Mat1b& mask, double share) {
  std::vector<float> samples;
  for (int y = 0; y < values.rows; ++y) {
    for (int x = 0; x < values.cols; ++x) {
      if (mask(y, x) && values(y, x) > 0.0f) samples.push_back(values(y, x));
    }
  }
  if (samples.empty()) return 0.0f;
  const auto nth = samples.begin() + static_cast<std::ptrdiff_t>(share * (samples.size() - 1));
  std::nth_element(samples.begin(), nth, samples.end());
  return *nth;
}

// Writes one person's depth into `depth` over `person_mask` (local to `target`): its nominal
// distance, moved in front of the real surface (`scene`) it covers and of people drawn before it
// (`people_depth`, 0 where none).
void paintDepth(const cv::Mat1f& scene, cv::Mat1f& depth, cv::Mat1f& people_depth,
                const cv::Rect& target, const cv::Mat1b& person_mask, double nominal_depth,
                const CompositeOptions& options) {
  const cv::Mat1f real = scene(target);
  double person_depth = nominal_depth;
  const float covered = positivePercentile(real, person_mask, 0.1);
  if (covered > 0.0f) person_depth = std::min(person_depth, covered - options.clearance_m);
  person_depth = std::max(person_depth, options.min_depth_m);
  for (int y = 0; y < target.height; ++y) {
    for (int x = 0; x < target.width; ++x) {
      if (!person_mask(y, x)) continue;
      float d = static_cast<float>(person_depth);
      if (real(y, x) > 0.0f) {
        d = std::min(d, real(y, x) - static_cast<float>(options.pixel_clearance_m));
      }
      float& previous_person = people_depth(target.y + y, target.x + x);
      if (previous_person > 0.0f) d = std::min(d, previous_person - 0.05f);
      d = std::max(d, static_cast<float>(options.min_depth_m) * 0.5f);
      depth(target.y + y, target.x + x) = d;
      previous_person = d;
    }
  }
}

}  // namespace

CompositeFrame compositePeople(const cv::Mat& image, const cv::Mat& depth_m, cv::Size image_size,
                               const std::vector<PersonPlacement>& placements,
                               const std::vector<PersonSprite>& sprites,
                               const CompositeOptions& options) {
  if (!image.empty() &&
      (image.size() != image_size || (image.type() != CV_8UC3 && image.type() != CV_8UC1))) {
    throw std::invalid_argument(
        "compositePeople: image must be 8-bit BGR or grey of the layout size");
  }
  if (!depth_m.empty() && (depth_m.size() != image_size || depth_m.type() != CV_32FC1)) {
    throw std::invalid_argument("compositePeople: depth must be CV_32FC1 of the layout size");
  }
  CompositeFrame frame;
  if (!image.empty()) frame.image = image.clone();
  if (!depth_m.empty()) frame.depth_m = depth_m.clone();
  frame.alpha = cv::Mat1f::zeros(image_size);
  std::vector<PersonLayer> layers;
  const cv::Rect image_rect(cv::Point(0, 0), image_size);

  for (const PersonPlacement& placement : placements) {
    if (placement.sprite >= sprites.size()) {
      throw std::out_of_range("compositePeople: placement refers to a missing sprite");
    }
    const ScaledSprite scaled = scaleSprite(sprites[placement.sprite], placement,
                                            image.empty() ? 0 : image.channels(), options);
    const cv::Rect target = cv::Rect(scaled.origin, scaled.alpha.size()) & image_rect;
    if (target.empty()) continue;
    const cv::Point offset = target.tl() - scaled.origin;
    const cv::Rect source_rect(offset, target.size());
    cv::Mat1f alpha = scaled.alpha(source_rect).clone();
    keepNearMask(alpha, featherRadius(options));

    if (!frame.image.empty()) {
      cv::Mat image_roi = frame.image(target);
      if (frame.image.channels() == 3) {
        blend<cv::Vec3b>(image_roi, scaled.color(source_rect), alpha);
      } else {
        blend<uchar>(image_roi, scaled.color(source_rect), alpha);
      }
    }
    const cv::Mat1f covered = frame.alpha(target);
    const cv::Mat1f combined = alpha + covered.mul(1.0f - alpha);
    combined.copyTo(frame.alpha(target));
    layers.push_back({target, alpha.clone(), placement.depth_m});
  }
  frame.mask = frame.alpha > 0.5f;
  if (!frame.depth_m.empty()) {
    // A pixel can be in the combined mask without any one person's alpha above 0.5 (two soft
    // edges overlapping): each person owns the mask pixels where its own alpha is noticeable.
    cv::Mat1f people_depth = cv::Mat1f::zeros(image_size);
    cv::Mat1f depth = frame.depth_m;
    for (const PersonLayer& layer : layers) {
      const cv::Mat1b person_mask = (layer.alpha > kDepthAlpha) & frame.mask(layer.target);
      paintDepth(depth_m, depth, people_depth, layer.target, person_mask, layer.depth_m, options);
    }
  }
  frame.coverage = static_cast<double>(cv::countNonZero(frame.mask)) / image_rect.area();
  return frame;
}

}  // namespace edgeslam
