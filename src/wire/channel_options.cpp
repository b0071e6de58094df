#include "wire/channel_options.h"

#include <algorithm>
#include <climits>

namespace edgeslam {
namespace {

int clampToInt(std::size_t value) {
  return static_cast<int>(std::min<std::size_t>(value, static_cast<std::size_t>(INT_MAX)));
}

}  // namespace

void applyServerChannelOptions(grpc::ServerBuilder& builder, std::size_t max_receive_bytes,
                               std::size_t max_send_bytes) {
  builder.SetMaxReceiveMessageSize(clampToInt(max_receive_bytes));
  builder.SetMaxSendMessageSize(clampToInt(max_send_bytes));
  builder.AddChannelArgument(GRPC_ARG_KEEPALIVE_TIME_MS, kKeepaliveTimeMs);
  builder.AddChannelArgument(GRPC_ARG_KEEPALIVE_TIMEOUT_MS, kKeepaliveTimeoutMs);
  builder.AddChannelArgument(GRPC_ARG_KEEPALIVE_PERMIT_WITHOUT_CALLS, 1);
  // Accept the clients' keepalive pings instead of answering them with GOAWAY.
  builder.AddChannelArgument(GRPC_ARG_HTTP2_MIN_RECV_PING_INTERVAL_WITHOUT_DATA_MS,
                             kKeepaliveTimeMs / 2);
  builder.AddChannelArgument(GRPC_ARG_HTTP2_MAX_PING_STRIKES, 0);
  builder.AddChannelArgument(GRPC_ARG_HTTP2_MAX_PINGS_WITHOUT_DATA, 0);
}

grpc::ChannelArguments clientChannelArguments(std::size_t max_receive_bytes,
                                              int reconnect_backoff_max_ms) {
  grpc::ChannelArguments args;
  args.SetMaxReceiveMessageSize(clampToInt(max_receive_bytes));
  args.SetMaxSendMessageSize(-1);  // the server enforces its own limit
  args.SetInt(GRPC_ARG_KEEPALIVE_TIME_MS, kKeepaliveTimeMs);
  args.SetInt(GRPC_ARG_KEEPALIVE_TIMEOUT_MS, kKeepaliveTimeoutMs);
  args.SetInt(GRPC_ARG_KEEPALIVE_PERMIT_WITHOUT_CALLS, 1);
  args.SetInt(GRPC_ARG_HTTP2_MAX_PINGS_WITHOUT_DATA, 0);
  args.SetInt(GRPC_ARG_INITIAL_RECONNECT_BACKOFF_MS, 100);
  args.SetInt(GRPC_ARG_MIN_RECONNECT_BACKOFF_MS, 100);
  args.SetInt(GRPC_ARG_MAX_RECONNECT_BACKOFF_MS, std::max(reconnect_backoff_max_ms, 100));
  // Each client gets its own connection (tests run several clients in one process).
  args.SetInt(GRPC_ARG_USE_LOCAL_SUBCHANNEL_POOL, 1);
  return args;
}

}  // namespace edgeslam
