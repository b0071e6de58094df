// The PNG / JPEG header reader on arbitrary bytes: never reads past the end, never throws.
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>

#include "wire/image_header.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  std::string error;
  const auto header = edgeslam::readImageHeader(std::span<const std::uint8_t>(data, size), &error);
  if (header) (void)header->decodedBytes();
  return 0;
}
