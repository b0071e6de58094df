#pragma once
// Test double of the edge session logic: records what reaches it and answers every keyframe with
// one slice, so the transport can be checked end to end without a SLAM back end.
#include <chrono>
#include <condition_variable>
#include <functional>
#include <memory>
#include <mutex>
#include <thread>
#include <vector>

#include "wire/edge_server.h"

namespace edgeslam::test {

// What one fake session saw; shared with the test so it outlives the backend.
struct FakeSessionLog {
  std::mutex mutex;
  std::condition_variable changed;
  SessionConfig config;
  std::vector<std::uint64_t> upload_sequences;
  std::vector<std::uint64_t> acknowledged_slices;
  int resync_requests = 0;
  bool destroyed = false;
  SliceSink* sink = nullptr;

  template <typename Predicate>
  bool waitFor(Predicate predicate, std::chrono::milliseconds timeout = std::chrono::seconds(10)) {
    std::unique_lock lock(mutex);
    return changed.wait_for(lock, timeout, [&] { return predicate(*this); });
  }
};

class FakeBackend final : public EdgeSessionBackend {
 public:
  FakeBackend(std::shared_ptr<FakeSessionLog> log, SliceSink& sink, bool offload)
      : log_(std::move(log)), sink_(sink), offload_(offload) {}
  ~FakeBackend() override {
    std::lock_guard lock(log_->mutex);
    log_->destroyed = true;
    log_->changed.notify_all();
  }

  void onKeyFrame(KeyFrameUpload upload) override {
    MapSlice slice;
    slice.upload_sequence = upload.sequence;
    slice.processed_keyframe = upload.keyframe.id;
    slice.points_upserted = upload.new_points;
    slice.reference_keyframe = upload.keyframe.id;
    slice.reference_pose = upload.keyframe.T_cw;
    sink_.push(std::move(slice));
    std::lock_guard lock(log_->mutex);
    log_->upload_sequences.push_back(upload.sequence);
    log_->acknowledged_slices.push_back(upload.acknowledged_slice);
    log_->changed.notify_all();
  }

  std::optional<OffloadResult> onFrame(OffloadFrame frame) override {
    if (!offload_) return std::nullopt;
    OffloadResult result;
    result.frame_index = frame.frame_index;
    result.state = OffloadTrackingState::kOk;
    result.T_cw = SE3d(Eigen::Quaterniond::Identity(),
                       Eigen::Vector3d(static_cast<double>(frame.frame_index), 0.0, 0.0));
    return result;
  }

  void onFullResyncRequested() override {
    MapSlice slice;
    slice.full_resync = true;
    sink_.push(std::move(slice));
    std::lock_guard lock(log_->mutex);
    ++log_->resync_requests;
    log_->changed.notify_all();
  }

 private:
  std::shared_ptr<FakeSessionLog> log_;
  SliceSink& sink_;
  bool offload_;
};

class FakeFactory final : public EdgeSessionFactory {
 public:
  explicit FakeFactory(bool offload = true) : offload_(offload) {}

  std::unique_ptr<EdgeSessionBackend> open(const SessionConfig& config, SliceSink& sink) override {
    auto log = std::make_shared<FakeSessionLog>();
    log->config = config;
    log->sink = &sink;
    {
      std::lock_guard lock(mutex_);
      logs_.push_back(log);
    }
    opened_.notify_all();
    return std::make_unique<FakeBackend>(log, sink, offload_);
  }

  std::shared_ptr<FakeSessionLog> session(
      std::size_t index, std::chrono::milliseconds timeout = std::chrono::seconds(10)) {
    std::unique_lock lock(mutex_);
    opened_.wait_for(lock, timeout, [&] { return logs_.size() > index; });
    return logs_.size() > index ? logs_[index] : nullptr;
  }

  std::size_t opened() {
    std::lock_guard lock(mutex_);
    return logs_.size();
  }

 private:
  bool offload_;
  std::mutex mutex_;
  std::condition_variable opened_;
  std::vector<std::shared_ptr<FakeSessionLog>> logs_;
};

// Collects slices delivered to a client callback.
struct SliceCollector {
  std::mutex mutex;
  std::condition_variable changed;
  std::vector<MapSlice> slices;

  std::function<void(MapSlice)> callback() {
    return [this](MapSlice slice) {
      std::lock_guard lock(mutex);
      slices.push_back(std::move(slice));
      changed.notify_all();
    };
  }
  bool waitForCount(std::size_t count,
                    std::chrono::milliseconds timeout = std::chrono::seconds(10)) {
    std::unique_lock lock(mutex);
    return changed.wait_for(lock, timeout, [&] { return slices.size() >= count; });
  }
  template <typename Predicate>
  bool waitForSlice(Predicate predicate,
                    std::chrono::milliseconds timeout = std::chrono::seconds(10)) {
    std::unique_lock lock(mutex);
    return changed.wait_for(lock, timeout, [&] {
      for (const MapSlice& s : slices) {
        if (predicate(s)) return true;
      }
      return false;
    });
  }
};

template <typename Predicate>
bool eventually(Predicate predicate, std::chrono::milliseconds timeout = std::chrono::seconds(10)) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  while (std::chrono::steady_clock::now() < deadline) {
    if (predicate()) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  return predicate();
}

}  // namespace edgeslam::test
