#pragma once
// The edge server inside the `run` command: a gRPC server on loopback (any free port), optionally
// behind the link emulator, so that one command exercises the real wire.
#include <functional>
#include <memory>
#include <optional>
#include <string>

#include "linkem/link_emulator.h"
#include "modes/slam_session_backend.h"
#include "wire/edge_server.h"

namespace edgeslam {

class EmbeddedEdge {
 public:
  // `wrap`, when given, stands between the server and its sessions' factory (the run command's
  // view of the sessions it opens).
  using FactoryWrapper =
      std::function<std::shared_ptr<EdgeSessionFactory>(std::shared_ptr<EdgeSessionFactory>)>;
  EmbeddedEdge(SlamSessionOptions options, std::optional<LinkSettings> link,
               const FactoryWrapper& wrap = {});
  ~EmbeddedEdge();

  // Where the client connects: the emulator when there is one, else the server.
  std::string clientAddress() const;
  EdgeServer& server() { return *server_; }

 private:
  std::unique_ptr<EdgeServer> server_;
  std::unique_ptr<LinkEmulator> emulator_;
};

}  // namespace edgeslam
