// ORB extraction and matching timings on real frames, with OpenCV's ORB as the baseline in the
// same run. Meant to be run pinned to one core (bench/run.sh does).
#include <benchmark/benchmark.h>
#include <fmt/format.h>

#include <opencv2/features2d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>

#include "bench_support.h"
#include "features/descriptor_matching.h"
#include "features/feature_grid.h"
#include "features/orb_extractor.h"
#include "features/steered_brief.h"

namespace edgeslam {
namespace {

const char* const kSevenScenes = "datasets/7scenes-redkitchen-1000/frame-000000.color.jpg";
const char* const kSevenScenesLater = "datasets/7scenes-redkitchen-1000/frame-000005.color.jpg";
const char* const kKitti = "datasets/kitti07-160/image_0/000000.png";

// Grey image, or empty with the benchmark marked skipped.
cv::Mat loadGrey(benchmark::State& state, const std::string& relative) {
  const auto path = bench::sharedPath(relative);
  cv::Mat image = cv::imread(path.string(), cv::IMREAD_GRAYSCALE);
  if (image.empty()) state.SkipWithError(("cannot read " + path.string()).c_str());
  return image;
}

void extractOurs(benchmark::State& state, const char* relative) {
  const cv::Mat image = loadGrey(state, relative);
  if (image.empty()) return;
  OrbExtractorOptions options;
  options.num_features = static_cast<int>(state.range(0));
  // A second argument: the pyramid's levels (the client's compute budget lowers both).
  if (state.range(1) > 0) options.num_levels = static_cast<int>(state.range(1));
  OrbExtractor extractor(options);
  std::vector<cv::KeyPoint> keypoints;
  cv::Mat descriptors;
  for (auto _ : state) {
    extractor.extract(image, keypoints, descriptors);
    benchmark::DoNotOptimize(descriptors.data);
  }
  state.counters["keypoints"] = static_cast<double>(keypoints.size());
}

void extractOpenCv(benchmark::State& state, const char* relative) {
  const cv::Mat image = loadGrey(state, relative);
  if (image.empty()) return;
  auto orb = cv::ORB::create(static_cast<int>(state.range(0)));
  std::vector<cv::KeyPoint> keypoints;
  cv::Mat descriptors;
  for (auto _ : state) {
    orb->detectAndCompute(image, cv::noArray(), keypoints, descriptors);
    benchmark::DoNotOptimize(descriptors.data);
  }
  state.counters["keypoints"] = static_cast<double>(keypoints.size());
}

void BM_OrbExtract_7Scenes(benchmark::State& state) {
  extractOurs(state, kSevenScenes);
}
void BM_CvOrb_7Scenes(benchmark::State& state) {
  extractOpenCv(state, kSevenScenes);
}
// Every frame of KITTI 07-160 in turn: frame 0 alone is less textured than the drive's average.
void extractSequence(benchmark::State& state, bool ours) {
  std::vector<cv::Mat> images;
  for (int i = 0; i < 160; i += 4) {
    images.push_back(loadGrey(state, fmt::format("datasets/kitti07-160/image_0/{:06d}.png", i)));
    if (images.back().empty()) return;
  }
  OrbExtractorOptions options;
  options.num_features = static_cast<int>(state.range(0));
  if (state.range(1) > 0) options.fast_threshold_min = static_cast<int>(state.range(1));
  OrbExtractor extractor(options);
  auto orb = cv::ORB::create(options.num_features);
  std::vector<cv::KeyPoint> keypoints;
  cv::Mat descriptors;
  std::size_t next = 0;
  for (auto _ : state) {
    const cv::Mat& image = images[next++ % images.size()];
    if (ours) {
      extractor.extract(image, keypoints, descriptors);
    } else {
      orb->detectAndCompute(image, cv::noArray(), keypoints, descriptors);
    }
    benchmark::DoNotOptimize(descriptors.data);
  }
  state.counters["keypoints"] = static_cast<double>(keypoints.size());
}

void BM_OrbExtract_KittiSequence(benchmark::State& state) {
  extractSequence(state, true);
}
void BM_CvOrb_KittiSequence(benchmark::State& state) {
  extractSequence(state, false);
}

void BM_OrbExtract_Kitti(benchmark::State& state) {
  extractOurs(state, kKitti);
}
void BM_CvOrb_Kitti(benchmark::State& state) {
  extractOpenCv(state, kKitti);
}

// The descriptor stage alone, ours against OpenCV's on the same level-0 keypoints.
std::vector<cv::KeyPoint> levelZeroKeypoints(OrbExtractor& extractor, const cv::Mat& image) {
  const OrbFeatures features = extractor.extract(image);
  std::vector<cv::KeyPoint> level0;
  for (const cv::KeyPoint& kp : features.keypoints) {
    if (kp.octave == 0) level0.push_back(kp);
  }
  return level0;
}

void BM_Describe_SteeredBrief(benchmark::State& state) {
  const cv::Mat image = loadGrey(state, kSevenScenes);
  if (image.empty()) return;
  OrbExtractor extractor;
  const auto keypoints = levelZeroKeypoints(extractor, image);
  cv::Mat blurred;
  cv::GaussianBlur(image, blurred, cv::Size(7, 7), 2.0, 2.0, cv::BORDER_REFLECT_101);
  cv::Mat descriptors(static_cast<int>(keypoints.size()), 32, CV_8UC1);
  for (auto _ : state) {
    computeSteeredBrief(blurred, keypoints, descriptors, 0);
    benchmark::DoNotOptimize(descriptors.data);
  }
  state.counters["keypoints"] = static_cast<double>(keypoints.size());
}

void BM_Describe_CvOrbCompute(benchmark::State& state) {
  const cv::Mat image = loadGrey(state, kSevenScenes);
  if (image.empty()) return;
  OrbExtractor extractor;
  const auto level0 = levelZeroKeypoints(extractor, image);
  cv::Mat blurred;
  cv::GaussianBlur(image, blurred, cv::Size(7, 7), 2.0, 2.0, cv::BORDER_REFLECT_101);
  auto orb = cv::ORB::create(1000, 1.2f, 1);
  std::vector<cv::KeyPoint> keypoints;
  cv::Mat descriptors;
  for (auto _ : state) {
    keypoints = level0;
    orb->compute(blurred, keypoints, descriptors);
    benchmark::DoNotOptimize(descriptors.data);
  }
  state.counters["keypoints"] = static_cast<double>(keypoints.size());
}

void BM_MatchInWindow_7Scenes(benchmark::State& state) {
  const cv::Mat first = loadGrey(state, kSevenScenes);
  const cv::Mat later = loadGrey(state, kSevenScenesLater);
  if (first.empty() || later.empty()) return;
  OrbExtractor extractor;
  const OrbFeatures a = extractor.extract(first);
  const OrbFeatures b = extractor.extract(later);
  const PinholeCamera::Bounds bounds{0.0, 640.0, 0.0, 480.0};
  std::size_t matches = 0;
  for (auto _ : state) {
    const FeatureGrid grid(bounds, b.keypoints);
    matches =
        matchInWindow(a.keypoints, a.descriptors, b.keypoints, b.descriptors, grid, 100.f).size();
    benchmark::DoNotOptimize(matches);
  }
  state.counters["matches"] = static_cast<double>(matches);
}

void BM_MatchBruteForce_7Scenes(benchmark::State& state) {
  const cv::Mat first = loadGrey(state, kSevenScenes);
  const cv::Mat later = loadGrey(state, kSevenScenesLater);
  if (first.empty() || later.empty()) return;
  OrbExtractor extractor;
  const OrbFeatures a = extractor.extract(first);
  const OrbFeatures b = extractor.extract(later);
  std::size_t matches = 0;
  for (auto _ : state) {
    matches = matchBruteForce(a.keypoints, a.descriptors, b.keypoints, b.descriptors).size();
    benchmark::DoNotOptimize(matches);
  }
  state.counters["matches"] = static_cast<double>(matches);
}

// Floors of the extraction on this machine: what any ORB extractor of 8 levels at scale 1.2 must
// do at least, with OpenCV's (vectorised) primitives: build the pyramid, detect FAST corners on
// every level (one threshold, no cells, no retry), blur each level for the descriptors. Describing
// is BM_Describe_CvOrbCompute's.
std::vector<cv::Mat> pyramidOf(const cv::Mat& image, int levels) {
  std::vector<cv::Mat> pyramid{image};
  double scale = 1.0;
  for (int level = 1; level < levels; ++level) {
    scale *= 1.2;
    cv::Mat next;
    cv::resize(image, next, cv::Size(cvRound(image.cols / scale), cvRound(image.rows / scale)), 0,
               0, cv::INTER_LINEAR);
    pyramid.push_back(std::move(next));
  }
  return pyramid;
}

void BM_Floor_Pyramid_7Scenes(benchmark::State& state) {
  const cv::Mat image = loadGrey(state, kSevenScenes);
  if (image.empty()) return;
  for (auto _ : state) {
    auto pyramid = pyramidOf(image, 8);
    benchmark::DoNotOptimize(pyramid.back().data);
  }
}

void BM_Floor_PyramidFast_7Scenes(benchmark::State& state) {
  const cv::Mat image = loadGrey(state, kSevenScenes);
  if (image.empty()) return;
  std::vector<cv::KeyPoint> keypoints;
  std::size_t found = 0;
  for (auto _ : state) {
    found = 0;
    for (const cv::Mat& level : pyramidOf(image, 8)) {
      cv::FAST(level, keypoints, 20, true);
      found += keypoints.size();
    }
    benchmark::DoNotOptimize(found);
  }
  state.counters["corners"] = static_cast<double>(found);
}

void BM_Floor_PyramidBlur_7Scenes(benchmark::State& state) {
  const cv::Mat image = loadGrey(state, kSevenScenes);
  if (image.empty()) return;
  cv::Mat blurred;
  for (auto _ : state) {
    for (const cv::Mat& level : pyramidOf(image, 8)) {
      cv::GaussianBlur(level, blurred, cv::Size(7, 7), 2.0, 2.0, cv::BORDER_REFLECT_101);
      benchmark::DoNotOptimize(blurred.data);
    }
  }
}

void configure(benchmark::internal::Benchmark* b) {
  b->Unit(benchmark::kMillisecond)->UseRealTime()->Repetitions(5)->ReportAggregatesOnly(true);
}

// The client's compute budget's steps (adapt/compute_budget.h): features and levels.
BENCHMARK(BM_OrbExtract_7Scenes)
    ->Args({1000, 8})
    ->Args({800, 8})
    ->Args({700, 6})
    ->Args({600, 5})
    ->Apply(configure);
BENCHMARK(BM_CvOrb_7Scenes)->Arg(1000)->Apply(configure);
BENCHMARK(BM_OrbExtract_Kitti)->Args({2000, 0})->Apply(configure);
BENCHMARK(BM_CvOrb_Kitti)->Arg(2000)->Apply(configure);
// Second argument: the retry threshold (0: the default 7; 20: no retry in empty cells).
BENCHMARK(BM_OrbExtract_KittiSequence)->Args({2000, 0})->Args({2000, 20})->Apply(configure);
BENCHMARK(BM_CvOrb_KittiSequence)->Args({2000, 0})->Apply(configure);
BENCHMARK(BM_Describe_SteeredBrief)->Apply(configure);
BENCHMARK(BM_Describe_CvOrbCompute)->Apply(configure);
BENCHMARK(BM_MatchInWindow_7Scenes)->Apply(configure);
BENCHMARK(BM_MatchBruteForce_7Scenes)->Apply(configure);
BENCHMARK(BM_Floor_Pyramid_7Scenes)->Apply(configure);
BENCHMARK(BM_Floor_PyramidFast_7Scenes)->Apply(configure);
BENCHMARK(BM_Floor_PyramidBlur_7Scenes)->Apply(configure);

}  // namespace
}  // namespace edgeslam

BENCHMARK_MAIN();
