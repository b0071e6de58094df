#pragma once
// Who may talk to an edge server, and over what: TLS (the server's certificate and key) and the
// clients' bearer tokens. Off loopback both are wanted (`edgeslam server` refuses to start
// without them unless told --insecure).
#include <memory>
#include <string>
#include <string_view>

#include "wire/access_tokens.h"

namespace edgeslam {

struct EdgeServerSecurity {
  std::string tls_certificate_pem;  // with the key: TLS; both empty: plaintext
  std::string tls_private_key_pem;
  std::shared_ptr<const AccessTokens> tokens;  // null: any client, no authorization metadata

  bool tls() const { return !tls_certificate_pem.empty(); }
};

// The metadata keys a client sends with every call.
constexpr const char* kAuthorizationMetadataKey = "authorization";  // "Bearer TOKEN"
// The map a session works on (a balancer routes on it too); absent: the default map.
constexpr const char* kMapMetadataKey = "edgeslam-map";
constexpr const char* kDefaultMapName = "default";

// True for addresses only this machine reaches: 127.0.0.0/8, ::1, localhost, unix sockets.
bool isLoopbackAddress(std::string_view listen_address);

// The whole content of a PEM file; std::runtime_error naming it when it cannot be read or does
// not look like PEM.
std::string readPemFile(const std::string& path, const char* what);

}  // namespace edgeslam
