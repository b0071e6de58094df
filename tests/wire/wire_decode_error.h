#pragma once
// The WireError message a malformed message gets from fromProto (a test failure, and an empty
// string, when it decodes).
#include <gtest/gtest.h>

#include <string>

#include "wire/wire_convert.h"
#include "wire/wire_error.h"

namespace edgeslam::test {

template <typename Message>
std::string decodeError(const Message& message) {
  try {
    (void)fromProto(message);
  } catch (const WireError& e) {
    return e.what();
  }
  ADD_FAILURE() << "decoding succeeded";
  return {};
}

}  // namespace edgeslam::test
