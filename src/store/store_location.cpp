#include "store/store_location.h"

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <ctime>
#include <stdexcept>

namespace edgeslam {

std::optional<std::filesystem::path> defaultMapStoreDirectory() {
  if (const char* xdg = std::getenv("XDG_DATA_HOME"); xdg != nullptr && *xdg == '/') {
    return std::filesystem::path(xdg) / "edgeslam";
  }
  if (const char* home = std::getenv("HOME"); home != nullptr && *home != '\0') {
    return std::filesystem::path(home) / ".local" / "share" / "edgeslam";
  }
  return std::nullopt;
}

std::string defaultMapName(const std::string& prefix) {
  const std::time_t now = std::chrono::system_clock::to_time_t(std::chrono::system_clock::now());
  std::tm utc{};
  gmtime_r(&now, &utc);
  char stamp[32];
  std::strftime(stamp, sizeof(stamp), "%Y%m%d-%H%M%S", &utc);
  std::string name = prefix.empty() ? std::string("map") : prefix;
  for (char& ch : name) {
    const bool safe = (ch >= 'a' && ch <= 'z') || (ch >= 'A' && ch <= 'Z') ||
                      (ch >= '0' && ch <= '9') || ch == '.' || ch == '_' || ch == '-';
    if (!safe) ch = '_';
  }
  if (name.front() == '.' || name.front() == '-') name.front() = '_';
  name = name.substr(0, 80);
  return name + "-" + stamp;
}

void checkMapName(const std::string& name) {
  const auto allowed = [](char c) {
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '.' ||
           c == '_' || c == '-';
  };
  if (name.empty() || name.size() > 100 || name.front() == '.' || name.front() == '-' ||
      !std::all_of(name.begin(), name.end(), allowed)) {
    throw std::invalid_argument("map name '" + name +
                                "': use letters, digits, '.', '_' and '-' (1 to 100 characters, "
                                "not starting with '.' or '-')");
  }
}

}  // namespace edgeslam
