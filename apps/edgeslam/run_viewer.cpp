#include "run_viewer.h"

#include <spdlog/spdlog.h>

#include <atomic>
#include <chrono>
#include <csignal>
#include <set>
#include <thread>
#include <utility>

namespace edgeslam::cli {
namespace {

std::atomic<bool> interrupted{false};

extern "C" void onInterrupt(int) {
  interrupted = true;
}

}  // namespace

RunViewer::RunViewer(const std::string& host, int port)
    : server_(std::make_unique<viz::ViewerServer>(
          viz::ViewerServerOptions{.host = host, .port = port}, view_)) {
  spdlog::info("viewer: {}", server_->url());
}

RunViewer::~RunViewer() {
  server_->stop();
}

RunViewer::Attachment::~Attachment() {
  view_->clearMapSampler();
}

std::unique_ptr<RunViewer::Attachment> RunViewer::attach(const SlamSystem& slam) {
  view_.setMapSampler([&slam](std::size_t max_points) { return slam.mapSample(max_points); });
  return std::make_unique<Attachment>(&view_);
}

void RunViewer::publishImage(const cv::Mat& image, const TrackResult& tracked,
                             const SemanticFrame* semantic, bool always) {
  viz::FrameImageSlot& images = *view_.images();
  if ((!always && !images.wanted()) || image.empty()) return;
  viz::FrameImage frame;
  frame.image = image.clone();
  frame.on_map = tracked.features_on_map;
  frame.fresh = tracked.features_new;
  if (semantic != nullptr && semantic->kept && semantic->all &&
      semantic->all->size() != semantic->kept->size()) {
    std::set<std::pair<float, float>> kept;
    for (const cv::KeyPoint& k : semantic->kept->keypoints) kept.emplace(k.pt.x, k.pt.y);
    for (const cv::KeyPoint& k : semantic->all->keypoints) {
      if (!kept.contains({k.pt.x, k.pt.y})) frame.culled.push_back(k.pt);
    }
  }
  if (semantic != nullptr) frame.mask = semantic->mask.clone();
  images.publish(std::move(frame));
}

void RunViewer::finish(double linger_seconds) {
  view_.markFinished();
  if (linger_seconds <= 0.0) return;
  spdlog::info("viewer: run finished; serving the final map at {} for {:.0f} s (Ctrl-C to stop)",
               server_->url(), linger_seconds);
  interrupted = false;
  struct sigaction action {};
  action.sa_handler = onInterrupt;
  sigemptyset(&action.sa_mask);
  struct sigaction previous {};
  sigaction(SIGINT, &action, &previous);
  const auto deadline =
      std::chrono::steady_clock::now() + std::chrono::duration<double>(linger_seconds);
  while (!interrupted && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  sigaction(SIGINT, &previous, nullptr);
  spdlog::info("viewer: stopped ({})", interrupted ? "interrupted" : "linger time over");
}

}  // namespace edgeslam::cli
