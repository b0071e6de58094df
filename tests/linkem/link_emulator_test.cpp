#include "linkem/link_emulator.h"

#include <gtest/gtest.h>
#include <sys/socket.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <sstream>
#include <thread>
#include <vector>

#include "linkem/socket.h"
#include "tcp_test_server.h"

namespace edgeslam {
namespace {

using test::echoHandler;
using test::recvAll;
using test::TcpTestServer;
using Clock = std::chrono::steady_clock;

double msBetween(Clock::time_point a, Clock::time_point b) {
  return std::chrono::duration<double, std::milli>(b - a).count();
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

LinkEmulator makeEmulator(const TcpTestServer& server, const LinkSettings& settings,
                          std::optional<LinkTrace> trace = std::nullopt) {
  LinkEmulatorOptions options;
  options.target = server.address();
  options.settings = settings;
  options.trace = std::move(trace);
  options.seed = 1234;
  return LinkEmulator(std::move(options));
}

SocketFd connectTo(const LinkEmulator& emulator) {
  SocketFd fd = connectTcp({"127.0.0.1", emulator.port()}, std::chrono::milliseconds(2000));
  setNoDelay(fd.get());
  return fd;
}

double echoRttMs(int fd, std::size_t bytes = 32) {
  std::vector<char> out(bytes, 'x');
  std::vector<char> in(bytes);
  const auto t0 = Clock::now();
  EXPECT_TRUE(sendAll(fd, out.data(), out.size()));
  EXPECT_TRUE(recvAll(fd, in.data(), in.size()));
  return msBetween(t0, Clock::now());
}

std::vector<char> pattern(std::size_t size) {
  std::vector<char> data(size);
  for (std::size_t i = 0; i < size; ++i) data[i] = static_cast<char>((i * 131 + i / 7) & 0xff);
  return data;
}

TEST(LinkEmulator, OneWayDelayAndRttMatchTheSettings) {
  // The server notes when each 32-byte message arrives: the same clock as the client's, so the
  // one-way delay is measurable directly.
  std::mutex mutex;
  std::vector<Clock::time_point> arrivals;
  TcpTestServer server([&](int fd) {
    char buffer[32];
    while (recvAll(fd, buffer, sizeof buffer)) {
      {
        std::lock_guard lock(mutex);
        arrivals.push_back(Clock::now());
      }
      if (!sendAll(fd, buffer, sizeof buffer)) break;
    }
  });
  LinkSettings settings;
  settings.delay_up_ms = 30.0;
  settings.delay_down_ms = 10.0;
  settings.up_mbps = 20.0;
  settings.down_mbps = 20.0;
  LinkEmulator emulator = makeEmulator(server, settings);
  emulator.start();
  SocketFd client = connectTo(emulator);
  // The emulator never delivers early, so every sample must be at least the setting; a loaded
  // machine wakes threads late (up to ~10 ms here with all cores busy), which only adds delay:
  // the fastest samples of up to three rounds show what the emulator itself does.
  double best_rtt = 1e9;
  double best_up = 1e9;
  double median_rtt = 0.0;
  double median_up = 0.0;
  for (int round = 0; round < 3; ++round) {
    std::vector<double> rtts;
    std::vector<double> one_way;
    for (int i = 0; i < 10; ++i) {
      const auto sent = Clock::now();
      rtts.push_back(echoRttMs(client.get()));
      std::lock_guard lock(mutex);
      one_way.push_back(msBetween(sent, arrivals.back()));
    }
    EXPECT_GE(*std::min_element(rtts.begin(), rtts.end()), 40.0);
    EXPECT_GE(*std::min_element(one_way.begin(), one_way.end()), 30.0);
    best_rtt = std::min(best_rtt, *std::min_element(rtts.begin(), rtts.end()));
    best_up = std::min(best_up, *std::min_element(one_way.begin(), one_way.end()));
    median_rtt = median(rtts);
    median_up = median(one_way);
    if (median_rtt < 42.0 && median_up < 31.5) break;
  }
  std::printf(
      "[ measured ] RTT min %.2f median %.2f ms (setting 40), one-way up min %.2f median "
      "%.2f ms (setting 30)\n",
      best_rtt, median_rtt, best_up, median_up);
  EXPECT_NEAR(best_rtt, 40.0, 4.0);
  EXPECT_NEAR(best_up, 30.0, 3.0);
}

TEST(LinkEmulator, ThroughputMatchesTheRateEachWay) {
  constexpr std::size_t kBytes = 2 * 1000 * 1000;
  const std::vector<char> data = pattern(kBytes);
  TcpTestServer server([&](int fd) {
    char command = 0;
    if (!recvAll(fd, &command, 1)) return;
    if (command == 'U') {
      std::vector<char> in(kBytes);
      if (!recvAll(fd, in.data(), in.size())) return;
      const char ok = in == data ? 'K' : 'E';
      sendAll(fd, &ok, 1);
    } else {
      sendAll(fd, data.data(), data.size());
    }
  });
  LinkSettings settings;
  settings.delay_up_ms = 20.0;
  settings.delay_down_ms = 20.0;
  settings.up_mbps = 20.0;
  settings.down_mbps = 20.0;
  LinkEmulator emulator = makeEmulator(server, settings);
  emulator.start();

  SocketFd up = connectTo(emulator);
  auto t0 = Clock::now();
  const char upload = 'U';
  ASSERT_TRUE(sendAll(up.get(), &upload, 1));
  ASSERT_TRUE(sendAll(up.get(), data.data(), data.size()));
  char reply = 0;
  ASSERT_TRUE(recvAll(up.get(), &reply, 1));
  EXPECT_EQ(reply, 'K');
  // Subtract one RTT: the first byte's trip up and the reply's trip down.
  const double up_mbps = (kBytes + 1) * 8.0 / ((msBetween(t0, Clock::now()) - 40.0) * 1e3);

  SocketFd down = connectTo(emulator);
  t0 = Clock::now();
  const char download = 'D';
  ASSERT_TRUE(sendAll(down.get(), &download, 1));
  std::vector<char> in(kBytes);
  ASSERT_TRUE(recvAll(down.get(), in.data(), in.size()));
  const double down_mbps = kBytes * 8.0 / ((msBetween(t0, Clock::now()) - 40.0) * 1e3);
  EXPECT_TRUE(in == data);
  std::printf("[ measured ] 2 MB at 20 Mbit/s: up %.2f Mbit/s, down %.2f Mbit/s\n", up_mbps,
              down_mbps);
  EXPECT_NEAR(up_mbps, 20.0, 2.0);
  EXPECT_NEAR(down_mbps, 20.0, 2.0);
  const LinkStats stats = emulator.stats();
  EXPECT_EQ(stats.bytes_up, kBytes + 2);
  EXPECT_EQ(stats.bytes_down, kBytes + 1);
  EXPECT_EQ(stats.connections_total, 2u);
}

TEST(LinkEmulator, JitterAndLossKeepTheStreamIntactAndInOrder) {
  TcpTestServer server(echoHandler);
  LinkSettings settings;
  settings.delay_up_ms = 5.0;
  settings.delay_down_ms = 5.0;
  settings.jitter_ms = 10.0;
  settings.up_mbps = 50.0;
  settings.down_mbps = 50.0;
  settings.loss = 0.02;
  LinkEmulator emulator = makeEmulator(server, settings);
  emulator.start();
  SocketFd client = connectTo(emulator);
  const std::vector<char> data = pattern(300 * 1000);
  std::thread sender([&] {
    // Small writes, so that many segments get their own jitter draw.
    for (std::size_t offset = 0; offset < data.size(); offset += 3000) {
      ASSERT_TRUE(sendAll(client.get(), data.data() + offset,
                          std::min<std::size_t>(3000, data.size() - offset)));
    }
  });
  std::vector<char> echoed(data.size());
  ASSERT_TRUE(recvAll(client.get(), echoed.data(), echoed.size()));
  sender.join();
  EXPECT_TRUE(echoed == data);
  EXPECT_GT(emulator.stats().lost_segments, 0u);

  // Jitter only adds delay: every RTT is at least the base, at most base + 2 * jitter plus
  // head-of-line waits behind earlier segments.
  std::vector<double> rtts;
  for (int i = 0; i < 15; ++i) rtts.push_back(echoRttMs(client.get()));
  EXPECT_GE(*std::min_element(rtts.begin(), rtts.end()), 10.0);
  EXPECT_GT(
      *std::max_element(rtts.begin(), rtts.end()) - *std::min_element(rtts.begin(), rtts.end()),
      2.0);
}

TEST(LinkEmulator, TraceReplaySwitchesRates) {
  // A sink that records how many bytes had arrived when.
  std::mutex mutex;
  std::vector<std::pair<Clock::time_point, std::size_t>> arrivals;
  TcpTestServer server([&](int fd) {
    std::vector<char> buffer(65536);
    std::size_t total = 0;
    while (true) {
      const ssize_t got = ::recv(fd, buffer.data(), buffer.size(), 0);
      if (got <= 0) break;
      total += static_cast<std::size_t>(got);
      std::lock_guard lock(mutex);
      arrivals.emplace_back(Clock::now(), total);
    }
  });
  std::istringstream text("0 4 4 1 1\n0.5 40 40 1 1\n");  // period 1 s
  LinkEmulator emulator = makeEmulator(server, LinkSettings{}, LinkTrace::parse(text, "inline"));
  emulator.start();
  const auto start = Clock::now();
  SocketFd client = connectTo(emulator);
  const std::vector<char> chunk(16384, 'a');
  while (msBetween(start, Clock::now()) < 960.0) {
    ASSERT_TRUE(sendAll(client.get(), chunk.data(), chunk.size()));
  }
  std::lock_guard lock(mutex);
  auto bytesAt = [&](double ms) {
    std::size_t bytes = 0;
    for (const auto& [t, total] : arrivals) {
      if (msBetween(start, t) <= ms) bytes = total;
    }
    return bytes;
  };
  const double slow = (bytesAt(450) - bytesAt(100)) * 8.0 / (350.0 * 1e3);
  const double fast = (bytesAt(950) - bytesAt(600)) * 8.0 / (350.0 * 1e3);
  std::printf("[ measured ] trace 4 -> 40 Mbit/s: %.2f -> %.2f Mbit/s\n", slow, fast);
  EXPECT_NEAR(slow, 4.0, 0.6);
  EXPECT_NEAR(fast, 40.0, 6.0);
}

TEST(LinkEmulator, SettingsChangeWhileRunning) {
  TcpTestServer server(echoHandler);
  LinkSettings settings;
  settings.delay_up_ms = 2.0;
  settings.delay_down_ms = 2.0;
  LinkEmulator emulator = makeEmulator(server, settings);
  emulator.start();
  SocketFd client = connectTo(emulator);
  const auto best = [&] {
    std::vector<double> rtts;
    for (int i = 0; i < 8; ++i) rtts.push_back(echoRttMs(client.get()));
    return *std::min_element(rtts.begin(), rtts.end());
  };
  const double before = best();
  settings.delay_up_ms = 20.0;
  settings.delay_down_ms = 20.0;
  emulator.setSettings(settings);
  const double after = best();
  // Wide upper bounds: only the change matters here (accuracy is checked above), and a loaded
  // machine adds wake-up delays.
  EXPECT_GE(before, 4.0);
  EXPECT_LT(before, 20.0);
  EXPECT_GE(after, 40.0);
  EXPECT_LT(after, 60.0);
  settings.loss = 2.0;
  EXPECT_THROW(emulator.setSettings(settings), std::invalid_argument);
}

TEST(LinkEmulator, ServesManyConnectionsAtOnce) {
  TcpTestServer server(echoHandler);
  LinkSettings settings;
  settings.delay_up_ms = 5.0;
  settings.delay_down_ms = 5.0;
  settings.up_mbps = 100.0;
  settings.down_mbps = 100.0;
  LinkEmulator emulator = makeEmulator(server, settings);
  emulator.start();
  constexpr int kClients = 8;
  constexpr std::size_t kBytes = 100 * 1000;
  std::vector<std::thread> clients;
  std::atomic<int> intact{0};
  for (int c = 0; c < kClients; ++c) {
    clients.emplace_back([&] {
      SocketFd fd = connectTo(emulator);
      const std::vector<char> data = pattern(kBytes);
      std::thread sender([&] { sendAll(fd.get(), data.data(), data.size()); });
      std::vector<char> echoed(kBytes);
      const bool ok = recvAll(fd.get(), echoed.data(), echoed.size());
      sender.join();
      if (ok && echoed == data) ++intact;
    });
  }
  for (auto& client : clients) client.join();
  EXPECT_EQ(intact.load(), kClients);
  // 800 kB each way share 100 Mbit/s per connection: no connection waits for another.
  const LinkStats stats = emulator.stats();
  EXPECT_EQ(stats.connections_total, static_cast<std::uint64_t>(kClients));
  EXPECT_EQ(stats.bytes_up, kClients * kBytes);
  EXPECT_EQ(stats.bytes_down, kClients * kBytes);
  // Closed clients are reaped.
  const auto deadline = Clock::now() + std::chrono::seconds(2);
  while (emulator.stats().connections_active > 0 && Clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  EXPECT_EQ(emulator.stats().connections_active, 0u);
}

TEST(LinkEmulator, StopsPromptlyWithBusyConnections) {
  TcpTestServer server(echoHandler);
  LinkSettings settings;
  settings.delay_up_ms = 200.0;
  settings.delay_down_ms = 200.0;
  settings.up_mbps = 1.0;
  settings.down_mbps = 1.0;
  LinkEmulator emulator = makeEmulator(server, settings);
  emulator.start();
  std::vector<SocketFd> clients;
  std::vector<std::thread> readers;
  const std::vector<char> data = pattern(200 * 1000);
  for (int c = 0; c < 3; ++c) {
    clients.push_back(connectTo(emulator));
    const int fd = clients.back().get();
    readers.emplace_back([fd, &data] {
      sendAll(fd, data.data(), data.size());
      std::vector<char> buffer(4096);
      while (::recv(fd, buffer.data(), buffer.size(), 0) > 0) {
      }
    });
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(100));
  EXPECT_EQ(emulator.stats().connections_active, 3u);
  const auto t0 = Clock::now();
  emulator.stop();
  EXPECT_LT(msBetween(t0, Clock::now()), 1000.0);
  EXPECT_FALSE(emulator.running());
  for (auto& reader : readers) reader.join();  // clients saw the close
  emulator.stop();                             // idempotent
}

TEST(LinkEmulator, DropsClientsWhenTheTargetRefuses) {
  std::uint16_t closed_port = 0;
  {
    SocketFd probe = listenTcp({"127.0.0.1", 0});
    closed_port = localPort(probe.get());
  }
  LinkEmulatorOptions options;
  options.target = {"127.0.0.1", closed_port};
  LinkEmulator emulator(options);
  emulator.start();
  SocketFd client = connectTo(emulator);
  char byte = 0;
  EXPECT_LE(::recv(client.get(), &byte, 1, 0), 0);
  EXPECT_EQ(emulator.stats().connect_failures, 1u);
  EXPECT_EQ(emulator.stats().connections_total, 0u);
}

TEST(LinkEmulator, StartFailsClearlyWhenThePortIsTaken) {
  SocketFd taken = listenTcp({"127.0.0.1", 0});
  LinkEmulatorOptions options;
  options.listen = {"127.0.0.1", localPort(taken.get())};
  options.target = {"127.0.0.1", 9};
  LinkEmulator emulator(options);
  try {
    emulator.start();
    FAIL() << "no exception";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("cannot listen on 127.0.0.1:"), std::string::npos);
  }
}

}  // namespace
}  // namespace edgeslam
