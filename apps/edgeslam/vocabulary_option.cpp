#include "vocabulary_option.h"

#include <spdlog/spdlog.h>

#include <cstdlib>
#include <filesystem>

#include "util/timing_stats.h"

namespace edgeslam::cli {

std::shared_ptr<const Vocabulary> loadVocabulary(const std::string& requested) {
  if (requested == "none") return nullptr;
  std::filesystem::path path = requested;
  if (path.empty()) {
    if (const char* env = std::getenv("EDGESLAM_VOCAB")) {
      path = env;
    } else {
      std::error_code error;
      const auto binary = std::filesystem::read_symlink("/proc/self/exe", error);
      if (!error) path = binary.parent_path() / "vocab" / "orb_k10_l5.vocab";
    }
    if (path.empty() || !std::filesystem::exists(path)) {
      spdlog::warn(
          "no vocabulary ({}): relocalisation tries recent keyframes only and loops are not "
          "closed; `make vocab` trains one, --vocab FILE names one",
          path.empty() ? "none found" : path.string() + " missing");
      return nullptr;
    }
  }
  Stopwatch timer;
  auto vocabulary = std::make_shared<const Vocabulary>(Vocabulary::load(path));
  spdlog::info("vocabulary {}: {} words, loaded in {:.0f} ms", path.string(),
               vocabulary->wordCount(), timer.elapsedMs());
  return vocabulary;
}

}  // namespace edgeslam::cli
