#pragma once
// A store that cannot be used: one line, naming the file.
#include <stdexcept>

namespace edgeslam {

class StoreError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace edgeslam
