#include "modes/first_map_frame.h"

namespace edgeslam {

void FirstMapFrame::noteProgress(std::size_t frames_recorded, std::size_t current_map) {
  current_map_.store(current_map);
  frames_recorded_.store(frames_recorded);
}

void FirstMapFrame::currentMapJoinedFirst() {
  const std::size_t map = current_map_.load();
  if (map == 0) return;
  const std::size_t from = frames_recorded_.load() + 1;
  MutexLock lock(mutex_);
  if (joined_from_.size() < map) joined_from_.resize(map);
  if (!joined_from_[map - 1]) joined_from_[map - 1] = from;
}

bool FirstMapFrame::inFirstAtFrameTime(std::size_t index, std::uint32_t map) const {
  if (map == 0) return true;
  MutexLock lock(mutex_);
  return map <= joined_from_.size() && joined_from_[map - 1] && index >= *joined_from_[map - 1];
}

bool FirstMapFrame::inFirstFinally(std::uint32_t map) const {
  if (map == 0) return true;
  MutexLock lock(mutex_);
  return map <= joined_from_.size() && joined_from_[map - 1].has_value();
}

}  // namespace edgeslam
