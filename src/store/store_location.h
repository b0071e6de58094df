#pragma once
// Where maps live unless told: the per-user data directory ($XDG_DATA_HOME/edgeslam, else
// ~/.local/share/edgeslam). `--maps none` means no store.
#include <filesystem>
#include <optional>
#include <string>

namespace edgeslam {

// nullopt when neither XDG_DATA_HOME nor HOME is set.
std::optional<std::filesystem::path> defaultMapStoreDirectory();

// A map name for a session that did not give one: `prefix`-YYYYMMDD-HHMMSS (UTC).
std::string defaultMapName(const std::string& prefix);

// Map names are file-name safe: letters, digits, '.', '_' and '-', 1 to 100 characters, not
// starting with '.' or '-'. Throws std::invalid_argument saying so.
void checkMapName(const std::string& name);

}  // namespace edgeslam
