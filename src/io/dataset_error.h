#pragma once
// The one exception type of the io part: bad or missing input, named by file (and line).
#include <stdexcept>

namespace edgeslam {

// Error with the offending file (and line, when a text file is malformed) in its message.
class DatasetError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace edgeslam
