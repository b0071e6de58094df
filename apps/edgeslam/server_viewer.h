#pragma once
// `server --viewer PORT`: the edge view beside an edge server. Started before the server (so a bad
// port ends the command before it listens); sees every session the server opens through the
// factory it wraps, and the server's per-session figures while attached.
#include <memory>
#include <string>

#include "viz/edge_view.h"
#include "viz/viewer_server.h"
#include "wire/edge_server.h"

namespace edgeslam::cli {

class ServerViewer {
 public:
  // Throws viz::ViewerError when the port cannot be served.
  ServerViewer(const std::string& host, int port);
  ~ServerViewer();
  ServerViewer(const ServerViewer&) = delete;
  ServerViewer& operator=(const ServerViewer&) = delete;

  int port() const { return server_->port(); }
  // `factory`, with every session it opens shown in the view.
  std::shared_ptr<EdgeSessionFactory> wrap(std::shared_ptr<EdgeSessionFactory> factory);

  // Shows `server`'s figures until the returned guard goes (declare it after the server).
  class Attachment {
   public:
    explicit Attachment(viz::EdgeView* view) : view_(view) {}
    ~Attachment();
    Attachment(const Attachment&) = delete;
    Attachment& operator=(const Attachment&) = delete;

   private:
    viz::EdgeView* view_;
  };
  [[nodiscard]] std::unique_ptr<Attachment> attach(const EdgeServer& server);
  // The maps of the server's store, listed and shown on request.
  void showStore(std::shared_ptr<MapStore> store) { view_.setStore(std::move(store)); }

 private:
  std::shared_ptr<viz::SessionDirectory> directory_;
  viz::EdgeView view_;
  std::unique_ptr<viz::ViewerServer> server_;
};

}  // namespace edgeslam::cli
