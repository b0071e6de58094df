#pragma once
// The clients an edge server lets in: a file of bearer tokens, one per line, each optionally
// limited to named maps (`TOKEN map1,map2`). Blank lines and lines starting with '#' are ignored.
#include <cstddef>
#include <filesystem>
#include <istream>
#include <string>
#include <string_view>
#include <vector>

namespace edgeslam {

struct AccessGrant {
  std::string token;
  std::vector<std::string> maps;  // empty: every map
  std::string label;              // names the client in logs and limits, never the token itself

  bool permitsMap(std::string_view map) const;
};

class AccessTokens {
 public:
  // Tokens are at least this long: a short one would be guessed.
  static constexpr std::size_t kMinTokenLength = 16;

  // Throws std::runtime_error naming `source` and the line for a malformed, short or repeated
  // token, and for a file without any.
  static AccessTokens parse(std::istream& in, const std::string& source);
  static AccessTokens load(const std::filesystem::path& file);

  // The grant of `token`, or nullptr. Compares in time independent of where tokens differ.
  const AccessGrant* find(std::string_view token) const;
  std::size_t size() const { return grants_.size(); }

 private:
  std::vector<AccessGrant> grants_;
};

// The token of an `authorization: Bearer TOKEN` metadata value, or "" when it has another form.
std::string_view bearerToken(std::string_view authorization);

}  // namespace edgeslam
