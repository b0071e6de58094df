#pragma once
// A stored map in the formats other tools open. Each session of the map is in its own frame;
// exports list every session's keyframes and points as they are (merging maps is not done yet).
#include <filesystem>

#include "store/map_store.h"

namespace edgeslam {

// TUM trajectory: one line per keyframe, `timestamp tx ty tz qx qy qz qw`, camera-to-world, by
// timestamp.
void exportTum(const StoredMap& map, const std::filesystem::path& file);
// Binary-free standard PLY (`element vertex`, x y z and a colour by height).
void exportPly(const StoredMap& map, const std::filesystem::path& file);
// COLMAP text model in `folder`: cameras.txt (one PINHOLE camera per session: keypoints are
// stored undistorted), images.txt (keyframes, with their keypoints and the points they see),
// points3D.txt (points with their tracks).
void exportColmap(const StoredMap& map, const std::filesystem::path& folder);

}  // namespace edgeslam
