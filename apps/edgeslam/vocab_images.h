#pragma once
// The training images of `edgeslam vocab train`: folders scanned recursively, text lists and
// single files, turned into one ordered list.
#include <cstddef>
#include <filesystem>
#include <string>
#include <vector>

namespace edgeslam::cli {

// Each argument is a folder (every .png / .jpg / .jpeg below it whose name does not contain
// "depth", sorted), a .txt list (one image per line, the last whitespace-separated field, so TUM's
// rgb.txt works too; relative paths are taken from the list's folder; '#' lines are comments) or
// an image file. Throws std::runtime_error naming the argument that gives nothing usable.
std::vector<std::filesystem::path> collectTrainingImages(const std::vector<std::string>& arguments);

// `max_count` images spread evenly over `images` (all of them when max_count is 0 or larger).
std::vector<std::filesystem::path> spreadSubset(const std::vector<std::filesystem::path>& images,
                                                std::size_t max_count);

}  // namespace edgeslam::cli
