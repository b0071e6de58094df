#include "modes/embedded_edge.h"

namespace edgeslam {

EmbeddedEdge::EmbeddedEdge(SlamSessionOptions options, std::optional<LinkSettings> link,
                           const FactoryWrapper& wrap) {
  std::shared_ptr<EdgeSessionFactory> factory = std::make_shared<SlamSessionFactory>(options);
  if (wrap) factory = wrap(std::move(factory));
  server_ = std::make_unique<EdgeServer>("127.0.0.1:0", std::move(factory));
  if (link) {
    LinkEmulatorOptions emulator;
    emulator.listen = {"127.0.0.1", 0};
    emulator.target = {"127.0.0.1", static_cast<std::uint16_t>(server_->port())};
    emulator.settings = *link;
    emulator_ = std::make_unique<LinkEmulator>(emulator);
    emulator_->start();
  }
}

EmbeddedEdge::~EmbeddedEdge() {
  if (emulator_) emulator_->stop();
  server_->shutdown();
}

std::string EmbeddedEdge::clientAddress() const {
  const int port = emulator_ ? emulator_->port() : server_->port();
  return "127.0.0.1:" + std::to_string(port);
}

}  // namespace edgeslam
