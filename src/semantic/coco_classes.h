#pragma once
// The COCO 80-class label set (the usual detector order, 0 = person) and the default set of
// movable classes whose pixels a SLAM system must not trust.
#include <string>
#include <string_view>
#include <vector>

namespace edgeslam {

constexpr int kCocoClassCount = 80;
constexpr int kCocoPerson = 0;

// Name of a COCO class id; throws std::out_of_range for ids outside [0, 80).
const std::string& cocoClassName(int class_id);

// Class id of a COCO name ("person", "traffic light"; '_' may stand for ' ', case-insensitive);
// -1 when unknown.
int cocoClassId(std::string_view name);

// person, bicycle, car, motorcycle, bus, truck and the animals (bird ... giraffe).
std::vector<int> defaultMovableClasses();

// Comma-separated class names ("person,car, dog"); "default" stands for defaultMovableClasses().
// Throws std::invalid_argument naming any unknown class, or when the list is empty. Sorted, unique.
std::vector<int> parseClassList(std::string_view comma_separated);

// "person,car" for a list of ids.
std::string classListToString(const std::vector<int>& class_ids);

}  // namespace edgeslam
