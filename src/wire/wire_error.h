#pragma once
#include <stdexcept>

namespace edgeslam {

// A message that cannot cross the wire: malformed on arrival (the server answers
// INVALID_ARGUMENT with this text) or a record that cannot be encoded.
class WireError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace edgeslam
