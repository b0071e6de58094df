// The vocabulary's binary file (docs/vocabulary.md): little-endian header, one record per node,
// FNV-1a 64 checksum of everything before it.
#include <fmt/format.h>

#include <array>
#include <cstring>
#include <fstream>
#include <stdexcept>

#include "place/fnv1a.h"
#include "place/vocabulary.h"

namespace edgeslam {
namespace {

constexpr std::array<std::uint8_t, 8> kMagic = {'E', 'S', 'V', 'O', 'C', 'A', 'B', 0x1A};
constexpr std::uint32_t kFormatVersion = 1;
constexpr std::size_t kHeaderBytes = 8 + 4 * 4 + 8 + 8 + 4 + 4;
constexpr std::size_t kNodeBytes = 4 + kDescriptorBytes + 8;
constexpr std::size_t kChecksumBytes = 8;

class ByteWriter {
 public:
  explicit ByteWriter(std::size_t reserve) { bytes_.reserve(reserve); }
  template <typename T>
  void put(T value) {
    std::array<std::uint8_t, sizeof(T)> raw;
    std::memcpy(raw.data(), &value, sizeof(T));
    bytes_.insert(bytes_.end(), raw.begin(), raw.end());
  }
  void putBytes(const std::uint8_t* data, std::size_t size) {
    bytes_.insert(bytes_.end(), data, data + size);
  }
  std::vector<std::uint8_t>& bytes() { return bytes_; }

 private:
  std::vector<std::uint8_t> bytes_;
};

// Reads from a buffer whose size was checked beforehand.
class ByteReader {
 public:
  explicit ByteReader(std::span<const std::uint8_t> bytes) : bytes_(bytes) {}
  template <typename T>
  T get() {
    T value;
    std::memcpy(&value, bytes_.data() + offset_, sizeof(T));
    offset_ += sizeof(T);
    return value;
  }
  const std::uint8_t* take(std::size_t size) {
    const std::uint8_t* at = bytes_.data() + offset_;
    offset_ += size;
    return at;
  }

 private:
  std::span<const std::uint8_t> bytes_;
  std::size_t offset_ = 0;
};

[[noreturn]] void fail(const std::string& source, const std::string& what) {
  throw std::runtime_error(fmt::format("vocabulary file '{}': {}", source, what));
}

}  // namespace

std::vector<std::uint8_t> Vocabulary::serialize() const {
  if (empty()) throw std::logic_error("cannot serialise an empty vocabulary");
  const std::size_t n = nodeCount();
  ByteWriter out(kHeaderBytes + n * kNodeBytes + kChecksumBytes);
  out.putBytes(kMagic.data(), kMagic.size());
  out.put<std::uint32_t>(kFormatVersion);
  out.put<std::uint32_t>(static_cast<std::uint32_t>(tree_.branching));
  out.put<std::uint32_t>(static_cast<std::uint32_t>(tree_.levels));
  out.put<std::uint32_t>(static_cast<std::uint32_t>(tree_.weighting));
  out.put<std::uint64_t>(tree_.training_images);
  out.put<std::uint64_t>(tree_.training_descriptors);
  out.put<std::uint32_t>(static_cast<std::uint32_t>(n));
  out.put<std::uint32_t>(static_cast<std::uint32_t>(wordCount()));
  std::array<std::uint8_t, kDescriptorBytes> centre{};
  for (std::size_t i = 0; i < n; ++i) {
    out.put<std::uint32_t>(tree_.parents[i]);
    tree_.centres[i].toBytes(centre.data());
    out.putBytes(centre.data(), centre.size());
    out.put<double>(tree_.weights[i]);
  }
  out.put<std::uint64_t>(fnv1a64(out.bytes()));
  return std::move(out.bytes());
}

std::uint64_t Vocabulary::checksum() const {
  const std::vector<std::uint8_t> bytes = serialize();
  std::uint64_t stored;
  std::memcpy(&stored, bytes.data() + bytes.size() - kChecksumBytes, kChecksumBytes);
  return stored;
}

Vocabulary Vocabulary::deserialize(std::span<const std::uint8_t> bytes, const std::string& source) {
  if (bytes.size() < kMagic.size() ||
      std::memcmp(bytes.data(), kMagic.data(), kMagic.size()) != 0) {
    fail(source, "not an edgeslam vocabulary (bad magic number)");
  }
  if (bytes.size() < kHeaderBytes + kChecksumBytes) {
    fail(source, fmt::format("truncated: {} bytes, the header alone needs {}", bytes.size(),
                             kHeaderBytes + kChecksumBytes));
  }
  ByteReader in(bytes);
  in.take(kMagic.size());
  const auto version = in.get<std::uint32_t>();
  if (version != kFormatVersion) {
    fail(source, fmt::format("unsupported format version {} (this build reads version {})", version,
                             kFormatVersion));
  }
  VocabularyTree tree;
  tree.branching = static_cast<int>(in.get<std::uint32_t>());
  tree.levels = static_cast<int>(in.get<std::uint32_t>());
  tree.weighting = static_cast<WordWeighting>(in.get<std::uint32_t>());
  tree.training_images = in.get<std::uint64_t>();
  tree.training_descriptors = in.get<std::uint64_t>();
  const auto node_count = in.get<std::uint32_t>();
  const auto word_count = in.get<std::uint32_t>();
  const std::uint64_t expected =
      kHeaderBytes + std::uint64_t{node_count} * kNodeBytes + kChecksumBytes;
  if (bytes.size() < expected) {
    fail(source,
         fmt::format("truncated: {} bytes, {} nodes need {}", bytes.size(), node_count, expected));
  }
  if (bytes.size() > expected) {
    fail(source, fmt::format("{} unexpected bytes after the checksum", bytes.size() - expected));
  }
  std::uint64_t stored;
  std::memcpy(&stored, bytes.data() + expected - kChecksumBytes, kChecksumBytes);
  const std::uint64_t computed = fnv1a64(bytes.first(expected - kChecksumBytes));
  if (stored != computed) {
    fail(source, fmt::format("checksum mismatch (stored {:#018x}, computed {:#018x}): the file is "
                             "corrupt",
                             stored, computed));
  }
  tree.parents.resize(node_count);
  tree.centres.resize(node_count);
  tree.weights.resize(node_count);
  for (std::uint32_t i = 0; i < node_count; ++i) {
    tree.parents[i] = in.get<std::uint32_t>();
    tree.centres[i] = Descriptor256::fromBytes(in.take(kDescriptorBytes));
    tree.weights[i] = in.get<double>();
  }
  try {
    Vocabulary vocabulary(std::move(tree));
    if (vocabulary.wordCount() != word_count) {
      fail(source, fmt::format("the header says {} words but the tree has {}", word_count,
                               vocabulary.wordCount()));
    }
    return vocabulary;
  } catch (const std::invalid_argument& e) {
    fail(source, e.what());
  }
}

Vocabulary Vocabulary::load(const std::filesystem::path& path) {
  std::ifstream file(path, std::ios::binary | std::ios::ate);
  if (!file) fail(path.string(), "cannot open (missing or unreadable)");
  const std::streamoff size = file.tellg();
  if (size < 0) fail(path.string(), "cannot determine the size");
  std::vector<std::uint8_t> bytes(static_cast<std::size_t>(size));
  file.seekg(0);
  if (!file.read(reinterpret_cast<char*>(bytes.data()), size)) fail(path.string(), "read error");
  return deserialize(bytes, path.string());
}

// Written beside the target and renamed, so that a reader never sees a half-written file.
void Vocabulary::save(const std::filesystem::path& path) const {
  const std::vector<std::uint8_t> bytes = serialize();
  std::filesystem::path temporary = path;
  temporary += ".partial";
  {
    std::ofstream file(temporary, std::ios::binary | std::ios::trunc);
    if (!file) fail(path.string(), "cannot create");
    file.write(reinterpret_cast<const char*>(bytes.data()),
               static_cast<std::streamsize>(bytes.size()));
    if (!file.flush()) fail(path.string(), "write error");
  }
  std::error_code error;
  std::filesystem::rename(temporary, path, error);
  if (error) fail(path.string(), "cannot rename the written file into place: " + error.message());
}

}  // namespace edgeslam
