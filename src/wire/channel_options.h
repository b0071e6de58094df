#pragma once
// gRPC settings shared by the edge server and the client: keepalive pings (so a vanished peer is
// noticed within seconds, even on an idle slice stream) and quick reconnection.
#include <grpcpp/grpcpp.h>

#include <cstddef>

namespace edgeslam {

constexpr int kKeepaliveTimeMs = 5000;
constexpr int kKeepaliveTimeoutMs = 5000;

void applyServerChannelOptions(grpc::ServerBuilder& builder, std::size_t max_receive_bytes,
                               std::size_t max_send_bytes);
grpc::ChannelArguments clientChannelArguments(std::size_t max_receive_bytes,
                                              int reconnect_backoff_max_ms);

}  // namespace edgeslam
