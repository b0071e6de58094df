#include "vocab_images.h"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace edgeslam::cli {
namespace {

namespace fs = std::filesystem;

std::string lower(std::string text) {
  std::transform(text.begin(), text.end(), text.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return text;
}

bool isImageFile(const fs::path& path) {
  const std::string extension = lower(path.extension().string());
  return extension == ".png" || extension == ".jpg" || extension == ".jpeg";
}

std::vector<fs::path> scanFolder(const fs::path& folder) {
  std::vector<fs::path> images;
  for (const auto& entry : fs::recursive_directory_iterator(folder)) {
    if (!entry.is_regular_file() || !isImageFile(entry.path())) continue;
    if (lower(entry.path().filename().string()).find("depth") != std::string::npos) continue;
    images.push_back(entry.path());
  }
  std::sort(images.begin(), images.end());
  return images;
}

std::vector<fs::path> readList(const fs::path& list) {
  std::ifstream in(list);
  if (!in) throw std::runtime_error(fmt::format("--images: cannot read list '{}'", list.string()));
  std::vector<fs::path> images;
  std::string line;
  int number = 0;
  while (std::getline(in, line)) {
    ++number;
    const auto first = line.find_first_not_of(" \t\r");
    if (first == std::string::npos || line[first] == '#') continue;
    std::istringstream fields(line);
    std::string field, last;
    while (fields >> field) last = field;
    fs::path path = fs::exists(line) ? fs::path(line) : fs::path(last);
    if (path.is_relative()) path = list.parent_path() / path;
    if (!fs::is_regular_file(path)) {
      throw std::runtime_error(fmt::format("--images: {} line {}: no image file '{}'",
                                           list.string(), number, path.string()));
    }
    images.push_back(path);
  }
  return images;
}

}  // namespace

std::vector<fs::path> collectTrainingImages(const std::vector<std::string>& arguments) {
  std::vector<fs::path> images;
  for (const std::string& argument : arguments) {
    const fs::path path(argument);
    std::vector<fs::path> found;
    if (fs::is_directory(path)) {
      found = scanFolder(path);
    } else if (fs::is_regular_file(path) && lower(path.extension().string()) == ".txt") {
      found = readList(path);
    } else if (fs::is_regular_file(path) && isImageFile(path)) {
      found = {path};
    } else if (!fs::exists(path)) {
      throw std::runtime_error(fmt::format("--images: '{}' does not exist", argument));
    } else {
      throw std::runtime_error(fmt::format(
          "--images: '{}' is not a folder, a .txt list or a .png/.jpg image", argument));
    }
    if (found.empty()) {
      throw std::runtime_error(fmt::format("--images: no images found in '{}'", argument));
    }
    images.insert(images.end(), found.begin(), found.end());
  }
  return images;
}

std::vector<fs::path> spreadSubset(const std::vector<fs::path>& images, std::size_t max_count) {
  if (max_count == 0 || images.size() <= max_count) return images;
  std::vector<fs::path> subset;
  subset.reserve(max_count);
  for (std::size_t i = 0; i < max_count; ++i)
    subset.push_back(images[i * images.size() / max_count]);
  return subset;
}

}  // namespace edgeslam::cli
