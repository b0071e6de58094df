// openDataset, format names and detection from the files a path holds.
#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <stdexcept>

#include "io/dataset.h"
#include "io/reader_support.h"
#include "io/readers.h"

namespace edgeslam {
namespace {

namespace fs = std::filesystem;

bool isEurocFolder(const fs::path& path) {
  return fs::exists(path / "mav0" / "cam0" / "data.csv") || fs::exists(path / "cam0" / "data.csv");
}

bool isSevenScenesFolder(const fs::path& path) {
  for (const auto& entry : fs::directory_iterator(path)) {
    if (detail::sevenScenesFrameNumber(entry.path().filename().string())) return true;
  }
  return false;
}

bool hasImages(const fs::path& path) {
  for (const auto& entry : fs::directory_iterator(path)) {
    if (entry.is_regular_file() && detail::isImageFile(entry.path())) return true;
  }
  return false;
}

}  // namespace

std::string toString(DatasetFormat format) {
  switch (format) {
    case DatasetFormat::kAuto:
      return "auto";
    case DatasetFormat::kTum:
      return "tum";
    case DatasetFormat::kKitti:
      return "kitti";
    case DatasetFormat::kEuroc:
      return "euroc";
    case DatasetFormat::kSevenScenes:
      return "7scenes";
    case DatasetFormat::kImages:
      return "images";
    case DatasetFormat::kVideo:
      return "video";
  }
  return "unknown";
}

DatasetFormat parseDatasetFormat(const std::string& name) {
  for (DatasetFormat format :
       {DatasetFormat::kAuto, DatasetFormat::kTum, DatasetFormat::kKitti, DatasetFormat::kEuroc,
        DatasetFormat::kSevenScenes, DatasetFormat::kImages, DatasetFormat::kVideo}) {
    if (name == toString(format)) return format;
  }
  throw std::invalid_argument(fmt::format(
      "unknown dataset format '{}' (expected auto|tum|kitti|euroc|7scenes|images|video)", name));
}

DatasetFormat detectDatasetFormat(const fs::path& path) {
  if (!fs::exists(path)) throw DatasetError(fmt::format("dataset not found: {}", path.string()));
  if (fs::is_regular_file(path)) {
    if (detail::isImageFile(path)) {
      throw DatasetError(fmt::format(
          "{} is a single image; pass the folder holding the images instead", path.string()));
    }
    return DatasetFormat::kVideo;  // any other file: let videoio try it
  }
  if (isEurocFolder(path)) return DatasetFormat::kEuroc;
  if (fs::exists(path / "rgb.txt")) return DatasetFormat::kTum;
  if (fs::is_directory(path / "image_0") && fs::exists(path / "times.txt")) {
    return DatasetFormat::kKitti;
  }
  if (isSevenScenesFolder(path)) return DatasetFormat::kSevenScenes;
  if (hasImages(path)) return DatasetFormat::kImages;
  throw DatasetError(fmt::format(
      "cannot tell the dataset format of {}: looked for mav0/cam0/data.csv (euroc), rgb.txt (tum), "
      "image_0/ with times.txt (kitti), frame-NNNNNN.color.png|jpg (7scenes), image files "
      "png|jpg|jpeg|bmp|ppm|pgm (images); a video must be given as a file. Pass --format to "
      "choose.",
      path.string()));
}

std::unique_ptr<DatasetReader> openDataset(const fs::path& path, const DatasetOptions& options) {
  const DatasetFormat format =
      options.format == DatasetFormat::kAuto ? detectDatasetFormat(path) : options.format;
  if (!fs::exists(path)) throw DatasetError(fmt::format("dataset not found: {}", path.string()));
  if (format != DatasetFormat::kVideo && !fs::is_directory(path)) {
    throw DatasetError(
        fmt::format("{}: a {} dataset is a folder, not a file", path.string(), toString(format)));
  }
  switch (format) {
    case DatasetFormat::kTum:
      return detail::openTumDataset(path, options);
    case DatasetFormat::kKitti:
      return detail::openKittiDataset(path, options);
    case DatasetFormat::kEuroc:
      return detail::openEurocDataset(path, options);
    case DatasetFormat::kSevenScenes:
      return detail::openSevenScenesDataset(path, options);
    case DatasetFormat::kImages:
      return detail::openImageFolderDataset(path, options);
    case DatasetFormat::kVideo:
      if (!fs::is_regular_file(path)) {
        throw DatasetError(fmt::format("{}: a video dataset is a file", path.string()));
      }
      return detail::openVideoDataset(path, options);
    case DatasetFormat::kAuto:
      break;
  }
  throw DatasetError("unreachable dataset format");
}

}  // namespace edgeslam
