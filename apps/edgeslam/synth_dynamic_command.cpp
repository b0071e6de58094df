// `edgeslam synth-dynamic`: a dynamic benchmark sequence from a real static one, with real people
// (cut out of photos by the segmenter) walking over the frames and per-frame ground-truth masks.
#include <fmt/format.h>

#include <chrono>
#include <iostream>
#include <memory>
#include <string>

#include "commands.h"
#include "semantic/segmenter.h"
#include "synth/dynamic_sequence.h"
#include "synth/person_sprite.h"

namespace edgeslam::cli {
namespace {

struct SynthDynamicCliOptions {
  std::string dataset;
  std::string format = "auto";
  std::string out;
  std::string people = defaultPeopleDirectory().string();
  std::string models = defaultModelDirectory().string();
  std::uint64_t seed = 1;
  std::string frames;
  int people_count = 0;
  double coverage = 22.0;
  bool overwrite = false;
  bool print_frames = false;
};

void runSynthDynamic(const SynthDynamicCliOptions& o) {
  DynamicSequenceOptions options;
  options.dataset = o.dataset;
  options.format = parseDatasetFormat(o.format);
  options.out = o.out;
  options.seed = o.seed;
  if (!o.frames.empty()) options.frames = parseFrameRange(o.frames);
  options.people_count = o.people_count;
  options.target_coverage = o.coverage / 100.0;
  options.overwrite = o.overwrite;
  options.people_dir = o.people;
  // Fail on a bad source or range before spending time on segmentation.
  {
    DatasetOptions dataset_options;
    dataset_options.format = options.format;
    const auto reader = openDataset(options.dataset, dataset_options);
    if (options.frames) checkFrameRange(*options.frames, reader->info().frame_count);
  }

  const auto started = std::chrono::steady_clock::now();
  SegmenterOptions segmenter_options;
  segmenter_options.model_dir = o.models;
  segmenter_options.classes = {0};  // person
  const auto segmenter = makeSegmenter(segmenter_options);
  const auto sprites = loadPeopleSprites(o.people, *segmenter);
  const double sprite_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  fmt::print("people: {} sprites from {} ({:.1f} s)\n", sprites.size(), o.people, sprite_s);
  for (const auto& sprite : sprites) {
    fmt::print("  {} box {}x{} at ({},{}) score {:.2f}\n", sprite.photo, sprite.box.width,
               sprite.box.height, sprite.box.x, sprite.box.y, sprite.score);
  }

  options.progress = [](std::size_t done, std::size_t total) {
    if (done % 25 == 0 || done == total) {
      std::cerr << fmt::format("\rcompositing frame {}/{}", done, total) << std::flush;
      if (done == total) std::cerr << '\n';
    }
  };
  const DynamicSequenceSummary summary = generateDynamicSequence(options, sprites);
  const CoverageStats& c = summary.coverage;
  if (o.print_frames) {
    for (std::size_t i = 0; i < summary.coverage_per_frame.size(); ++i) {
      fmt::print("frame {:4d} coverage {:5.1f} %\n", i, 100.0 * summary.coverage_per_frame[i]);
    }
  }
  fmt::print("wrote {} frames{} to {} in {:.1f} s ({} people, base body height {:.0f} px)\n",
             summary.frames, summary.has_depth ? " with depth" : "", summary.out.string(),
             summary.elapsed_s, summary.people, summary.base_height_px);
  fmt::print(
      "people coverage on the {} frames showing someone: median {:.1f} %, range {:.1f}-{:.1f} %, "
      "p10-p90 {:.1f}-{:.1f} %\n",
      c.frames_with_people, 100.0 * c.median, 100.0 * c.min, 100.0 * c.max, 100.0 * c.p10,
      100.0 * c.p90);
  fmt::print("run it: edgeslam run --dataset {} --format auto --sensor {}\n", summary.out.string(),
             summary.has_depth ? "mono|rgbd" : "mono");
}

}  // namespace

void addSynthDynamicCommand(CLI::App& app) {
  auto options = std::make_shared<SynthDynamicCliOptions>();
  auto* command = app.add_subcommand(
      "synth-dynamic",
      "Make a dynamic benchmark sequence: real people (cut out of photos by the segmenter) walk "
      "over a real static sequence; writes a TUM RGB-D folder (rgb/, depth/ when the source has "
      "depth, groundtruth.txt, camera.yaml) plus ground-truth masks/ + masks.txt and synth.json");
  command->add_option("--dataset", options->dataset, "Source dataset folder")->required();
  command->add_option("--format", options->format, "Source dataset format")
      ->check(CLI::IsMember({"auto", "tum", "kitti", "euroc", "7scenes", "images", "video"}))
      ->capture_default_str();
  command->add_option("--out", options->out, "Output folder (created; must be empty)")->required();
  command->add_option("--people", options->people, "Folder of photos with people to cut out")
      ->capture_default_str();
  command->add_option("--models", options->models, "Folder holding the segmenter's ONNX models")
      ->capture_default_str();
  command->add_option("--seed", options->seed, "Random seed: same seed, same sequence")
      ->capture_default_str();
  command->add_option("--frames", options->frames,
                      "Source frame indices A-B (inclusive, 0-based); default all");
  command
      ->add_option("--num-people", options->people_count,
                   "People in the sequence, 1-3 (0 = drawn from the seed)")
      ->check(CLI::Range(0, 3))
      ->capture_default_str();
  command
      ->add_option("--coverage", options->coverage,
                   "Target median share of the image covered by people, in % (frames with people)")
      ->check(CLI::Range(1.0, 90.0))
      ->capture_default_str();
  command->add_flag("--overwrite", options->overwrite,
                    "Replace the generated files in a non-empty --out folder");
  command->add_flag("--print-frames", options->print_frames, "Print the coverage of every frame");
  command->callback([options] {
    try {
      runSynthDynamic(*options);
      exitCode() = 0;
    } catch (const CLI::Error&) {
      throw;  // a usage error: main() reports it
    } catch (const std::exception& e) {
      std::cerr << "edgeslam synth-dynamic: error: " << e.what() << std::endl;
      exitCode() = 1;
    }
  });
}

const CommandRegistration kSynthDynamicRegistration{75, addSynthDynamicCommand};

}  // namespace edgeslam::cli
