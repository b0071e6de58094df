// `edgeslam vocab train|info`: build a bag-of-words vocabulary from images, inspect a file.
#include <fmt/format.h>

#include <atomic>
#include <filesystem>
#include <iostream>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

#include "commands.h"
#include "features/orb_extractor.h"
#include "place/parallel_for.h"
#include "place/vocabulary_training.h"
#include "progress_line.h"
#include "util/mutex.h"
#include "util/timing_stats.h"
#include "vocab_images.h"

namespace edgeslam::cli {
namespace {

namespace fs = std::filesystem;

struct TrainOptions {
  std::vector<std::string> images;
  std::string out;
  int k = 10;
  int levels = 5;
  int features = 1000;
  int threads = 0;
  std::uint64_t seed = 0;
  std::size_t max_images = 0;
  int iterations = 10;
  std::string weighting = "tf-idf";
};

struct InfoOptions {
  std::string file;
  bool json = false;
};

std::vector<cv::Mat> extractDescriptors(const std::vector<fs::path>& images, int features,
                                        int threads, ProgressLine& progress) {
  OrbExtractorOptions orb;
  orb.num_features = features;
  orb.validate();
  std::vector<OrbExtractor> extractors(static_cast<std::size_t>(threads), OrbExtractor(orb));
  std::vector<cv::Mat> descriptors(images.size());
  std::atomic<std::size_t> done{0};
  std::atomic<std::size_t> count{0};
  Mutex progress_mutex;
  parallelFor(images.size(), threads, [&](std::size_t i, int worker) {
    const cv::Mat image = cv::imread(images[i].string(), cv::IMREAD_GRAYSCALE);
    if (image.empty()) throw std::runtime_error("cannot read image " + images[i].string());
    std::vector<cv::KeyPoint> keypoints;
    extractors[static_cast<std::size_t>(worker)].extract(image, keypoints, descriptors[i]);
    count += static_cast<std::size_t>(descriptors[i].rows);
    const std::size_t finished = ++done;
    const MutexLock lock(progress_mutex);
    progress.update(fmt::format("extracting ORB  {}/{} images  {} descriptors", finished,
                                images.size(), count.load()),
                    finished == images.size());
  });
  progress.finish();
  return descriptors;
}

void runTrain(const TrainOptions& o) {
  const Stopwatch total_clock;
  VocabularyTrainingOptions training;
  training.branching = o.k;
  training.levels = o.levels;
  training.max_iterations = o.iterations;
  training.seed = o.seed;
  training.weighting = parseWordWeighting(o.weighting);
  training.threads = o.threads > 0 ? o.threads : hardwareThreads();
  training.validate();
  if (o.features < 1) throw std::invalid_argument(fmt::format("--features {} < 1", o.features));

  const std::vector<fs::path> images = spreadSubset(collectTrainingImages(o.images), o.max_images);
  const fs::path out(o.out);
  if (out.has_parent_path()) fs::create_directories(out.parent_path());

  ProgressLine progress;
  const Stopwatch extraction_clock;
  const std::vector<cv::Mat> descriptors =
      extractDescriptors(images, o.features, training.threads, progress);
  const double extraction_s = extraction_clock.elapsedMs() / 1000.0;

  const Stopwatch training_clock;
  std::string last_stage;
  training.progress = [&](const VocabularyTrainingProgress& p) {
    const bool new_stage = p.stage != last_stage;
    last_stage = p.stage;
    progress.update(fmt::format("training k={} L={}  {} {:.0f}%", o.k, o.levels, p.stage,
                                p.total == 0 ? 100.0
                                             : 100.0 * static_cast<double>(p.done) /
                                                   static_cast<double>(p.total)),
                    new_stage || p.done == p.total);
  };
  const Vocabulary vocabulary = trainVocabulary(descriptors, training);
  const double training_s = training_clock.elapsedMs() / 1000.0;
  progress.finish();
  vocabulary.save(out);

  fmt::print("vocabulary   {}\n", out.string());
  fmt::print("images       {}\n", images.size());
  fmt::print("descriptors  {}\n", vocabulary.tree().training_descriptors);
  fmt::print("words        {} ({} nodes, k={} L={}, {})\n", vocabulary.wordCount(),
             vocabulary.nodeCount(), o.k, o.levels, toString(vocabulary.weighting()));
  fmt::print("threads      {}\n", training.threads);
  fmt::print("time         extraction {:.1f} s, training {:.1f} s, total {:.1f} s\n", extraction_s,
             training_s, total_clock.elapsedMs() / 1000.0);
}

void runInfo(const InfoOptions& o) {
  const Stopwatch clock;
  const Vocabulary vocabulary = Vocabulary::load(o.file);
  const double load_ms = clock.elapsedMs();
  const auto file_bytes = fs::file_size(o.file);
  const VocabularyTree& tree = vocabulary.tree();
  if (o.json) {
    const nlohmann::json out = {{"file", o.file},
                                {"k", vocabulary.branching()},
                                {"levels", vocabulary.levels()},
                                {"weighting", std::string(toString(vocabulary.weighting()))},
                                {"words", vocabulary.wordCount()},
                                {"nodes", vocabulary.nodeCount()},
                                {"training_images", tree.training_images},
                                {"training_descriptors", tree.training_descriptors},
                                {"file_bytes", file_bytes},
                                {"checksum_ok", true},
                                {"checksum", fmt::format("{:016x}", vocabulary.checksum())},
                                {"load_ms", load_ms}};
    std::cout << out.dump(2) << std::endl;
    return;
  }
  fmt::print("file         {}\n", o.file);
  fmt::print("k            {}\n", vocabulary.branching());
  fmt::print("levels       {}\n", vocabulary.levels());
  fmt::print("weighting    {}\n", toString(vocabulary.weighting()));
  fmt::print("words        {}\n", vocabulary.wordCount());
  fmt::print("nodes        {}\n", vocabulary.nodeCount());
  fmt::print("trained on   {} images, {} descriptors\n", tree.training_images,
             tree.training_descriptors);
  fmt::print("file size    {} bytes\n", file_bytes);
  fmt::print("checksum     ok (fnv1a64 {:016x})\n", vocabulary.checksum());
  fmt::print("load time    {:.1f} ms\n", load_ms);
}

template <typename Run, typename Options>
void setCallback(CLI::App* command, const char* name, std::shared_ptr<Options> options, Run run) {
  command->callback([options, name, run] {
    try {
      run(*options);
      exitCode() = 0;
    } catch (const CLI::Error&) {
      throw;  // a usage error: main() reports it
    } catch (const std::exception& e) {
      std::cerr << "edgeslam vocab " << name << ": error: " << e.what() << std::endl;
      exitCode() = 1;
    }
  });
}

}  // namespace

void addVocabCommands(CLI::App& app) {
  auto* vocab = app.add_subcommand("vocab", "Train and inspect bag-of-words vocabularies");
  vocab->require_subcommand(1);

  auto train_options = std::make_shared<TrainOptions>();
  auto* train = vocab->add_subcommand(
      "train",
      "Train a vocabulary (hierarchical k-medians over ORB descriptors, tf-idf weights) from "
      "images and save it");
  train
      ->add_option("--images", train_options->images,
                   "Folders (scanned recursively for .png/.jpg, skipping names containing "
                   "'depth'), .txt lists of image paths, or image files")
      ->required()
      ->expected(1, -1);
  train->add_option("--out", train_options->out, "Vocabulary file to write")->required();
  train->add_option("--k", train_options->k, "Branching factor")
      ->check(CLI::Range(2, 256))
      ->capture_default_str();
  train->add_option("--levels", train_options->levels, "Depth of the tree (L)")
      ->check(CLI::Range(1, 16))
      ->capture_default_str();
  train->add_option("--features", train_options->features, "ORB features per image")
      ->check(CLI::Range(1, 100000))
      ->capture_default_str();
  train->add_option("--threads", train_options->threads, "Threads (0: all hardware threads)")
      ->check(CLI::Range(0, 1024))
      ->capture_default_str();
  train->add_option("--seed", train_options->seed, "Random seed (the result depends on it only)")
      ->capture_default_str();
  train
      ->add_option("--max-images", train_options->max_images,
                   "Use at most this many images, spread evenly over the list (0: all)")
      ->capture_default_str();
  train->add_option("--iterations", train_options->iterations, "k-medians rounds per node")
      ->check(CLI::Range(1, 1000000))
      ->capture_default_str();
  train->add_option("--weighting", train_options->weighting, "Word weighting")
      ->check(CLI::IsMember({"tf-idf", "tf", "idf", "binary"}))
      ->capture_default_str();
  setCallback(train, "train", train_options, runTrain);

  auto info_options = std::make_shared<InfoOptions>();
  auto* info = vocab->add_subcommand(
      "info", "Check a vocabulary file (checksum, structure) and print its k, L, words, nodes");
  info->add_option("file", info_options->file, "Vocabulary file")->required();
  info->add_flag("--json", info_options->json, "Print exactly one JSON object");
  setCallback(info, "info", info_options, runInfo);
}

const CommandRegistration kVocabCommandsRegistration{60, addVocabCommands};

}  // namespace edgeslam::cli
