#pragma once
// Command-line options for TLS and client tokens: `server --tls-cert/--tls-key/--auth-tokens/
// --insecure` and `client --tls-ca/--token` (docs/security.md).
#include <CLI/CLI.hpp>
#include <string>

#include "wire/edge_client.h"
#include "wire/edge_server.h"

namespace edgeslam::cli {

struct ServerSecurityOptions {
  std::string tls_cert;
  std::string tls_key;
  std::string auth_tokens;
  bool insecure = false;
  std::size_t max_sessions_per_token = EdgeServerLimits{}.max_sessions_per_client;
  double max_uploads_per_second = EdgeServerLimits{}.max_uploads_per_second;
  std::size_t max_message_mb = EdgeServerLimits{}.max_message_bytes >> 20;
};

void addServerSecurityOptions(CLI::App& command, ServerSecurityOptions& options);

// Checks a --listen value: HOST:PORT with a port in 0..65535, [IPV6]:PORT, or unix:PATH.
CLI::Validator listenAddress();

// Refuses (CLI::ValidationError: a usage error) to serve an address off loopback without TLS and
// tokens unless --insecure; reads the files (std::runtime_error when they are unreadable).
EdgeServerSecurity loadServerSecurity(const ServerSecurityOptions& options,
                                      const std::string& listen_address);

// The server's limits with the ones given on the command line.
EdgeServerLimits serverLimits(const ServerSecurityOptions& options);

struct ClientSecurityOptions {
  std::string tls_ca;
  std::string token;  // default: $EDGESLAM_TOKEN
};

void addClientSecurityOptions(CLI::App& command, ClientSecurityOptions& options);

EdgeClientCredentials loadClientCredentials(const ClientSecurityOptions& options);

}  // namespace edgeslam::cli
