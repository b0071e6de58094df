#include "semantic/coco_classes.h"

#include <algorithm>
#include <array>
#include <cctype>
#include <stdexcept>

namespace edgeslam {
namespace {

const std::array<std::string, kCocoClassCount>& cocoNames() {
  static const std::array<std::string, kCocoClassCount> names = {
      "person",        "bicycle",      "car",
      "motorcycle",    "airplane",     "bus",
      "train",         "truck",        "boat",
      "traffic light", "fire hydrant", "stop sign",
      "parking meter", "bench",        "bird",
      "cat",           "dog",          "horse",
      "sheep",         "cow",          "elephant",
      "bear",          "zebra",        "giraffe",
      "backpack",      "umbrella",     "handbag",
      "tie",           "suitcase",     "frisbee",
      "skis",          "snowboard",    "sports ball",
      "kite",          "baseball bat", "baseball glove",
      "skateboard",    "surfboard",    "tennis racket",
      "bottle",        "wine glass",   "cup",
      "fork",          "knife",        "spoon",
      "bowl",          "banana",       "apple",
      "sandwich",      "orange",       "broccoli",
      "carrot",        "hot dog",      "pizza",
      "donut",         "cake",         "chair",
      "couch",         "potted plant", "bed",
      "dining table",  "toilet",       "tv",
      "laptop",        "mouse",        "remote",
      "keyboard",      "cell phone",   "microwave",
      "oven",          "toaster",      "sink",
      "refrigerator",  "book",         "clock",
      "vase",          "scissors",     "teddy bear",
      "hair drier",    "toothbrush"};
  return names;
}

std::string normalized(std::string_view name) {
  std::string out;
  for (char c : name) {
    out.push_back(c == '_' ? ' ' : static_cast<char>(std::tolower(static_cast<unsigned char>(c))));
  }
  const auto first = out.find_first_not_of(" \t");
  if (first == std::string::npos) return {};
  const auto last = out.find_last_not_of(" \t");
  return out.substr(first, last - first + 1);
}

}  // namespace

const std::string& cocoClassName(int class_id) {
  if (class_id < 0 || class_id >= kCocoClassCount) {
    throw std::out_of_range("COCO class id " + std::to_string(class_id) + " is outside [0, 80)");
  }
  return cocoNames()[static_cast<std::size_t>(class_id)];
}

int cocoClassId(std::string_view name) {
  const std::string wanted = normalized(name);
  const auto& names = cocoNames();
  const auto it = std::find(names.begin(), names.end(), wanted);
  return it == names.end() ? -1 : static_cast<int>(it - names.begin());
}

std::vector<int> defaultMovableClasses() {
  // person, bicycle, car, motorcycle, bus, truck, then bird ... giraffe (ids 14-23).
  std::vector<int> ids = {0, 1, 2, 3, 5, 7};
  for (int id = 14; id <= 23; ++id) ids.push_back(id);
  return ids;
}

std::vector<int> parseClassList(std::string_view comma_separated) {
  std::vector<int> ids;
  std::size_t start = 0;
  while (start <= comma_separated.size()) {
    const std::size_t comma = std::min(comma_separated.find(',', start), comma_separated.size());
    const std::string item = normalized(comma_separated.substr(start, comma - start));
    start = comma + 1;
    if (item.empty()) continue;
    if (item == "default") {
      const auto defaults = defaultMovableClasses();
      ids.insert(ids.end(), defaults.begin(), defaults.end());
      continue;
    }
    const int id = cocoClassId(item);
    if (id < 0) {
      throw std::invalid_argument("unknown class '" + item +
                                  "' (expected COCO class names such as person, car, dog)");
    }
    ids.push_back(id);
  }
  if (ids.empty()) {
    throw std::invalid_argument("the class list '" + std::string(comma_separated) +
                                "' names no class");
  }
  std::sort(ids.begin(), ids.end());
  ids.erase(std::unique(ids.begin(), ids.end()), ids.end());
  return ids;
}

std::string classListToString(const std::vector<int>& class_ids) {
  std::string out;
  for (int id : class_ids) {
    if (!out.empty()) out += ',';
    out += cocoClassName(id);
  }
  return out;
}

}  // namespace edgeslam
