#pragma once
// The error every evaluation step throws on input it cannot evaluate (message names the cause).
#include <stdexcept>

namespace edgeslam {

class EvalError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace edgeslam
