#pragma once
// Where tracking hands its new keyframes: the local mapper in-process, or the uplink to the edge.
#include <cstddef>

namespace edgeslam {

class KeyFrame;

class KeyFrameSink {
 public:
  virtual ~KeyFrameSink() = default;
  // The keyframe is already in the map with its observations linked.
  virtual void insertKeyFrame(KeyFrame* keyframe) = 0;
  // False while the mapper has a backlog: tracking then holds back optional keyframes.
  virtual bool acceptsKeyFrames() const = 0;
  // Whether a keyframe tracking cannot do without (it is starving) may still go in: a little
  // more backlog than acceptsKeyFrames() allows, bounded all the same.
  virtual bool acceptsUrgentKeyFrames() const { return acceptsKeyFrames(); }
  // Index of the frame whose keyframe was last optimised into the map (keyframe rule 2).
  virtual std::size_t lastOptimizedFrame() const = 0;
  // True while no map update can come (the edge is unreachable): an overdue update is then no
  // reason for a keyframe.
  virtual bool mapUpdatesPaused() const { return false; }
  // The map was emptied (a failed start): forget queued keyframes.
  virtual void onMapReset() = 0;
};

}  // namespace edgeslam
