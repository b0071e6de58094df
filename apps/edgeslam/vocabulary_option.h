#pragma once
// The `--vocab` option of run, client and server: which bag-of-words vocabulary to load.
#include <memory>
#include <string>

#include "place/vocabulary.h"

namespace edgeslam::cli {

// "" = $EDGESLAM_VOCAB, else vocab/orb_k10_l5.vocab next to the binary (a warning and nullptr when
// absent); "none" = nullptr; anything else is a file that must load (throws naming it).
std::shared_ptr<const Vocabulary> loadVocabulary(const std::string& requested);

}  // namespace edgeslam::cli
