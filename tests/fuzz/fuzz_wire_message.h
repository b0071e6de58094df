#pragma once
// One libFuzzer entry point per wire message: the bytes are parsed as that protobuf message (what
// gRPC does with a request) and then decoded and validated as the edge server or the client does.
// A WireError is a correct refusal; anything else escaping, or a sanitizer report, is a bug.
#include <cstddef>
#include <cstdint>

#include "wire/wire_error.h"

#define EDGESLAM_FUZZ_WIRE_MESSAGE(MessageType, decode)                               \
  extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) { \
    MessageType message;                                                              \
    if (!message.ParseFromArray(data, static_cast<int>(size))) return 0;              \
    try {                                                                             \
      decode(message);                                                                \
    } catch (const ::edgeslam::WireError&) {                                          \
    }                                                                                 \
    return 0;                                                                         \
  }
