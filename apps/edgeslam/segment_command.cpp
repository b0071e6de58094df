// `edgeslam segment`: instance segmentation of movable objects in images, drawn as overlays.
#include <fmt/format.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <opencv2/core/utility.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>

#include "commands.h"
#include "segment_truth_score.h"
#include "semantic/coco_classes.h"
#include "semantic/label_encoding.h"
#include "semantic/segmentation_overlay.h"
#include "semantic/segmenter.h"
#include "util/timing_stats.h"
#include "wire/image_header.h"

namespace edgeslam::cli {
namespace {

namespace fs = std::filesystem;

struct SegmentOptions {
  std::string image;
  std::string images;
  std::string out;
  std::string models = defaultModelDirectory().string();
  std::string backend = "centernet-selfie";
  std::string classes = "default";
  float nm = 0.8f;
  float score = 0.3f;
  float border_score = SegmenterOptions{}.border_score_threshold;
  float other_score = SegmenterOptions{}.other_classes_score_threshold;
  int repeat = 1;
  int mask_downscale = 2;
  int threads = 0;
  int input_size = 512;
  int reduce = 1;
  std::string truth;
  int every = 1;
};

bool isImageFile(const fs::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext == ".png" || ext == ".jpg" || ext == ".jpeg";
}

std::vector<fs::path> listImages(const fs::path& folder) {
  if (!fs::is_directory(folder)) {
    throw std::invalid_argument("--images " + folder.string() + " is not a folder");
  }
  std::vector<fs::path> images;
  for (const auto& entry : fs::directory_iterator(folder)) {
    if (entry.is_regular_file() && isImageFile(entry.path())) images.push_back(entry.path());
  }
  std::sort(images.begin(), images.end());
  if (images.empty()) {
    throw std::invalid_argument("--images " + folder.string() + " holds no .png or .jpg file");
  }
  return images;
}

void segmentOne(Segmenter& segmenter, const fs::path& input, const fs::path& output,
                const SegmentOptions& o) {
  // The header first: a file that is no image fails here, before the decoders print their own
  // complaints on stderr.
  std::ifstream file(input, std::ios::binary);
  std::vector<std::uint8_t> head(4096);
  file.read(reinterpret_cast<char*>(head.data()), static_cast<std::streamsize>(head.size()));
  head.resize(static_cast<std::size_t>(file.gcount()));
  std::string header_error;
  if (!file.is_open() || !readImageHeader(head, &header_error)) {
    throw std::runtime_error("cannot read image " + input.string() +
                             (file.is_open() ? ": " + header_error : ""));
  }
  cv::Mat image = cv::imread(input.string(), cv::IMREAD_COLOR);
  if (image.empty()) throw std::runtime_error("cannot read image " + input.string());
  if (o.reduce > 1) {
    // As keyframes reach the edge: reduced on the client.
    cv::resize(
        image, image,
        cv::Size((image.cols + o.reduce - 1) / o.reduce, (image.rows + o.reduce - 1) / o.reduce), 0,
        0, cv::INTER_AREA);
  }
  Segmentation segmentation;
  SampleStats times;
  for (int i = 0; i < std::max(1, o.repeat); ++i) {
    segmentation = segmenter.segment(image);
    times.add(segmentation.elapsed_ms);
  }
  std::string encoding;
  const auto mask_bytes = encodeLabelImage(segmentation.label_image, o.mask_downscale, encoding);
  fmt::print("{} ({}x{}): {} instances, {:.1f} ms{}, label image {} bytes ({})\n",
             input.filename().string(), image.cols, image.rows, segmentation.instances.size(),
             times.summary().median, o.repeat > 1 ? fmt::format(" (median of {})", o.repeat) : "",
             mask_bytes.size(), encoding);
  for (const auto& instance : segmentation.instances) {
    fmt::print("  {:<12} {:.2f}  box x={} y={} w={} h={}  mask {}\n", instance.class_name,
               instance.score, instance.box.x, instance.box.y, instance.box.width,
               instance.box.height, instance.mask_is_box ? "box" : "pixels");
  }
  if (!output.empty()) {
    if (!cv::imwrite(output.string(), drawSegmentation(image, segmentation))) {
      throw std::runtime_error("cannot write overlay " + output.string());
    }
  }
}

void runSegment(const SegmentOptions& o) {
  if ((o.image.empty() ? 0 : 1) + (o.images.empty() ? 0 : 1) + (o.truth.empty() ? 0 : 1) != 1) {
    throw CLI::ValidationError(
        "give exactly one of --image FILE, --images DIR or --truth GENERATED_SEQUENCE");
  }
  if (o.threads > 0) cv::setNumThreads(o.threads);
  SegmenterOptions options;
  options.backend = o.backend;
  options.model_dir = o.models;
  options.classes = parseClassList(o.classes);
  options.nms_threshold = o.nm;
  options.score_threshold = o.score;
  options.border_score_threshold = o.border_score;
  options.other_classes_score_threshold = o.other_score;
  options.detector_input_size = o.input_size;
  const auto segmenter = makeSegmenter(options);
  fmt::print(
      "segmenter {} (models {}), classes {}, nm {:.2f}, score {:.2f} ({:.2f} at the image's "
      "sides, {:.2f} for classes other than people)\n",
      segmenter->backendName(), options.model_dir.string(), classListToString(options.classes),
      o.nm, o.score, o.border_score, o.other_score);
  if (!o.truth.empty()) {
    scoreSegmenterOnSequence(*segmenter, o.truth, {o.every, o.reduce});
    return;
  }
  if (!o.image.empty()) {
    segmentOne(*segmenter, o.image, o.out, o);
    return;
  }
  if (!o.out.empty()) fs::create_directories(o.out);
  for (const fs::path& input : listImages(o.images)) {
    const fs::path output =
        o.out.empty() ? fs::path() : fs::path(o.out) / (input.stem().string() + ".png");
    segmentOne(*segmenter, input, output, o);
  }
}

}  // namespace

void addSegmentCommand(CLI::App& app) {
  auto options = std::make_shared<SegmentOptions>();
  auto* segment = app.add_subcommand(
      "segment",
      "Segment people and other movable objects in images; print the instances and time, and "
      "draw overlays (coloured masks, boxes, labels)");
  segment->add_option("--image", options->image, "One input image (.png/.jpg)");
  segment->add_option("--images", options->images, "A folder: every .png/.jpg in it");
  segment->add_option("--truth", options->truth,
                      "A sequence made by `edgeslam synth-dynamic`: segment its frames and score "
                      "them against its ground-truth masks (IoU, people missed, false alarms)");
  segment->add_option("--every", options->every, "With --truth: score every Nth frame")
      ->check(CLI::Range(1, 100000))
      ->capture_default_str();
  segment->add_option("--out", options->out,
                      "Overlay PNG (with --image) or output folder (with --images); "
                      "nothing is written when absent");
  segment->add_option("--models", options->models, "Folder holding the ONNX models")
      ->capture_default_str();
  segment->add_option("--backend", options->backend, "Segmentation backend")
      ->check(CLI::IsMember(segmenterBackends()))
      ->capture_default_str();
  segment
      ->add_option("--classes", options->classes,
                   "Comma-separated COCO class names to segment; 'default' = people, vehicles "
                   "and animals")
      ->capture_default_str();
  segment->add_option("--nm", options->nm, "Box NMS IoU threshold (paper Table I: 0.6-0.8)")
      ->check(CLI::Range(0.0f, 1.0f))
      ->capture_default_str();
  segment->add_option("--score", options->score, "Detection score threshold")
      ->check(CLI::Range(0.0f, 1.0f))
      ->capture_default_str();
  segment
      ->add_option("--border-score", options->border_score,
                   "Detection score threshold for boxes that reach the image's left or right "
                   "edge (people walking into view score lower)")
      ->check(CLI::Range(0.0f, 1.0f))
      ->capture_default_str();
  segment
      ->add_option("--other-score", options->other_score,
                   "Detection score threshold for classes other than people, wherever the box is")
      ->check(CLI::Range(0.0f, 1.0f))
      ->capture_default_str();
  segment
      ->add_option("--repeat", options->repeat,
                   "Segment each image N times and report the median time")
      ->check(CLI::Range(1, 1000))
      ->capture_default_str();
  segment
      ->add_option("--mask-downscale", options->mask_downscale,
                   "Downscale for the reported wire size of the label image")
      ->check(CLI::Range(1, 16))
      ->capture_default_str();
  segment
      ->add_option("--input-size", options->input_size,
                   "Side of the detector's square input (multiple of 32; trained at 512)")
      ->capture_default_str();
  segment
      ->add_option("--reduce", options->reduce,
                   "Shrink each image N times first (keyframes reach the edge at 1/2)")
      ->check(CLI::Range(1, 16))
      ->capture_default_str();
  segment
      ->add_option("--threads", options->threads,
                   "CPU threads for OpenCV (0 = OpenCV's default, all cores)")
      ->check(CLI::Range(0, 256))
      ->capture_default_str();
  segment->callback([options] {
    try {
      runSegment(*options);
      exitCode() = 0;
    } catch (const CLI::Error&) {
      throw;  // a usage error: main() reports it
    } catch (const std::exception& e) {
      std::cerr << "edgeslam segment: error: " << e.what() << std::endl;
      exitCode() = 1;
    }
  });
}

const CommandRegistration kSegmentCommandRegistration{70, addSegmentCommand};

}  // namespace edgeslam::cli
