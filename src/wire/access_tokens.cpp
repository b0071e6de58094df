#include "wire/access_tokens.h"

#include <fmt/format.h>

#include <algorithm>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace edgeslam {
namespace {

bool constantTimeEqual(std::string_view a, std::string_view b) {
  if (a.size() != b.size()) return false;
  unsigned char difference = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    difference |= static_cast<unsigned char>(a[i] ^ b[i]);
  }
  return difference == 0;
}

bool isTokenCharacter(char c) {
  return c > ' ' && c < 127;
}

std::vector<std::string> splitMaps(const std::string& list) {
  std::vector<std::string> maps;
  std::stringstream in(list);
  std::string map;
  while (std::getline(in, map, ',')) {
    if (map.empty()) throw std::invalid_argument("empty map name in '" + list + "'");
    maps.push_back(map);
  }
  return maps;
}

}  // namespace

bool AccessGrant::permitsMap(std::string_view map) const {
  return maps.empty() || std::find(maps.begin(), maps.end(), map) != maps.end();
}

AccessTokens AccessTokens::parse(std::istream& in, const std::string& source) {
  AccessTokens tokens;
  std::string line;
  for (int number = 1; std::getline(in, line); ++number) {
    const auto fail = [&](const std::string& why) {
      return std::runtime_error(fmt::format("{} line {}: {}", source, number, why));
    };
    if (!line.empty() && line.back() == '\r') line.pop_back();
    std::istringstream fields(line);
    std::string token;
    if (!(fields >> token) || token.front() == '#') continue;
    if (!std::all_of(token.begin(), token.end(), isTokenCharacter)) {
      throw fail("a token is printable ASCII");
    }
    if (token.size() < kMinTokenLength) {
      throw fail(fmt::format("a token has at least {} characters (this one {})", kMinTokenLength,
                             token.size()));
    }
    AccessGrant grant;
    std::string maps;
    if (fields >> maps) {
      try {
        grant.maps = splitMaps(maps);
      } catch (const std::invalid_argument& e) {
        throw fail(e.what());
      }
    }
    std::string extra;
    if (fields >> extra) throw fail("expected TOKEN [MAP,MAP...], found more");
    if (tokens.find(token) != nullptr) throw fail("the token is listed twice");
    grant.token = std::move(token);
    grant.label = fmt::format("token #{} ({}:{})", tokens.grants_.size() + 1, source, number);
    tokens.grants_.push_back(std::move(grant));
  }
  if (tokens.grants_.empty()) throw std::runtime_error(source + " holds no token");
  return tokens;
}

AccessTokens AccessTokens::load(const std::filesystem::path& file) {
  std::ifstream in(file);
  if (!in || std::filesystem::is_directory(file)) {
    throw std::runtime_error("cannot read the token file " + file.string());
  }
  return parse(in, file.string());
}

const AccessGrant* AccessTokens::find(std::string_view token) const {
  const AccessGrant* found = nullptr;
  for (const AccessGrant& grant : grants_) {
    if (constantTimeEqual(grant.token, token)) found = &grant;
  }
  return found;
}

std::string_view bearerToken(std::string_view authorization) {
  constexpr std::string_view kScheme = "Bearer ";
  if (authorization.size() <= kScheme.size() ||
      authorization.substr(0, kScheme.size()) != kScheme) {
    return {};
  }
  return authorization.substr(kScheme.size());
}

}  // namespace edgeslam
