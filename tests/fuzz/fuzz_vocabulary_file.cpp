// Vocabulary files (`--vocab`): header, tree, weights and checksum trailer.
#include <exception>

#include "fuzz_file.h"
#include "place/vocabulary.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto path = edgeslam::fuzz::writeInput("words.vocab", data, size);
  try {
    (void)edgeslam::Vocabulary::load(path);
  } catch (const std::exception&) {
  }
  return 0;
}
