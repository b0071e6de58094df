#include "server_viewer.h"

#include <spdlog/spdlog.h>

namespace edgeslam::cli {

ServerViewer::ServerViewer(const std::string& host, int port)
    : directory_(std::make_shared<viz::SessionDirectory>()),
      view_(directory_),
      server_(std::make_unique<viz::ViewerServer>(
          viz::ViewerServerOptions{.host = host, .port = port}, view_)) {
  spdlog::info("viewer: {}", server_->url());
}

ServerViewer::~ServerViewer() {
  server_->stop();
}

std::shared_ptr<EdgeSessionFactory> ServerViewer::wrap(
    std::shared_ptr<EdgeSessionFactory> factory) {
  return std::make_shared<viz::ViewedSessionFactory>(std::move(factory), directory_);
}

ServerViewer::Attachment::~Attachment() {
  view_->clearStatsSource();
}

std::unique_ptr<ServerViewer::Attachment> ServerViewer::attach(const EdgeServer& server) {
  view_.setStatsSource([&server] { return server.sessions(); });
  return std::make_unique<Attachment>(&view_);
}

}  // namespace edgeslam::cli
