#include "network_security_options.h"

#include <spdlog/spdlog.h>

#include <cstdlib>

namespace edgeslam::cli {

void addServerSecurityOptions(CLI::App& command, ServerSecurityOptions& options) {
  auto* cert = command.add_option("--tls-cert", options.tls_cert,
                                  "TLS certificate chain (PEM) the server presents");
  auto* key = command.add_option("--tls-key", options.tls_key, "Private key (PEM) of --tls-cert");
  cert->needs(key);
  key->needs(cert);
  command.add_option("--auth-tokens", options.auth_tokens,
                     "File of client tokens, one per line: TOKEN [MAP,MAP...] (a token limited "
                     "to maps opens sessions on those only); without it any client is let in");
  command.add_flag("--insecure", options.insecure,
                   "Serve an address off loopback without TLS or tokens (anyone who reaches the "
                   "port can use and read every map)");
  command
      .add_option("--max-sessions-per-token", options.max_sessions_per_token,
                  "Sessions one client token may hold open at once")
      ->check(CLI::Range(std::size_t{1}, std::size_t{255}))
      ->capture_default_str();
  command
      .add_option("--max-upload-rate", options.max_uploads_per_second,
                  "Keyframe uploads and offloaded frames a second per session (0 = no limit)")
      ->check(CLI::Range(0.0, 1e6))
      ->capture_default_str();
  command.add_option("--max-message-mb", options.max_message_mb, "Largest request accepted (MiB)")
      ->check(CLI::Range(std::size_t{1}, std::size_t{1024}))
      ->capture_default_str();
}

CLI::Validator listenAddress() {
  return CLI::Validator(
      [](std::string& value) -> std::string {
        if (value.rfind("unix:", 0) == 0) return value.size() > 5 ? "" : "unix: needs a path";
        const std::size_t colon = value.rfind(':');
        if (colon == std::string::npos || colon == 0) return "expected HOST:PORT, got " + value;
        const std::string port = value.substr(colon + 1);
        if (port.empty() || port.size() > 5 ||
            port.find_first_not_of("0123456789") != std::string::npos || std::stoi(port) > 65535) {
          return "the port of " + value + " is not a number in 0..65535";
        }
        return "";
      },
      "HOST:PORT", "listen address");
}

EdgeServerSecurity loadServerSecurity(const ServerSecurityOptions& options,
                                      const std::string& listen_address) {
  const bool tls = !options.tls_cert.empty();
  const bool tokens = !options.auth_tokens.empty();
  if (!isLoopbackAddress(listen_address) && !(tls && tokens) && !options.insecure) {
    throw CLI::ValidationError(
        "--listen", listen_address + " is reachable from other machines: give --tls-cert, " +
                        "--tls-key and --auth-tokens (docs/security.md), or --insecure");
  }
  EdgeServerSecurity security;
  if (tls) {
    security.tls_certificate_pem = readPemFile(options.tls_cert, "TLS certificate");
    security.tls_private_key_pem = readPemFile(options.tls_key, "TLS key");
  }
  if (tokens) {
    security.tokens = std::make_shared<const AccessTokens>(AccessTokens::load(options.auth_tokens));
  }
  if (!isLoopbackAddress(listen_address) && !(tls && tokens)) {
    spdlog::warn("serving {} {}: --insecure", listen_address,
                 tls      ? "without client tokens"
                 : tokens ? "without TLS"
                          : "without TLS or tokens");
  }
  return security;
}

EdgeServerLimits serverLimits(const ServerSecurityOptions& options) {
  EdgeServerLimits limits;
  limits.max_sessions_per_client = options.max_sessions_per_token;
  limits.max_uploads_per_second = options.max_uploads_per_second;
  limits.max_message_bytes = options.max_message_mb << 20;
  return limits;
}

void addClientSecurityOptions(CLI::App& command, ClientSecurityOptions& options) {
  command.add_option("--tls-ca", options.tls_ca,
                     "Talk TLS to the server and check its certificate against this CA (PEM)");
  command.add_option("--token", options.token,
                     "Client token the server knows (default: $EDGESLAM_TOKEN); prefer the "
                     "variable, a command line is visible to other users");
}

EdgeClientCredentials loadClientCredentials(const ClientSecurityOptions& options) {
  EdgeClientCredentials credentials;
  if (!options.tls_ca.empty()) credentials.tls_ca_pem = readPemFile(options.tls_ca, "TLS CA");
  credentials.token = options.token;
  if (credentials.token.empty()) {
    if (const char* env = std::getenv("EDGESLAM_TOKEN"); env != nullptr) credentials.token = env;
  }
  return credentials;
}

}  // namespace edgeslam::cli
