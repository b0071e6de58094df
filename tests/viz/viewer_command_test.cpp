// `edgeslam run --viewer` as a user runs it: the viewer serves the live run, lingers on the final
// map until Ctrl-C, and a port it cannot serve is a clear error before any frame.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <httplib.h>
#include <poll.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <nlohmann/json.hpp>
#include <string>
#include <thread>
#include <vector>

#include "support/edgeslam_command.h"
#include "support/shared_data.h"

namespace edgeslam {
namespace {

using namespace std::chrono_literals;

constexpr char kDataset[] = "datasets/7scenes-redkitchen-1000";

// The binary started in the background, its stdout and stderr read as they come.
class BackgroundRun {
 public:
  explicit BackgroundRun(const std::vector<std::string>& arguments) {
    int fds[2];
    if (pipe(fds) != 0) return;
    pid_ = fork();
    if (pid_ == 0) {
      dup2(fds[1], STDOUT_FILENO);
      dup2(fds[1], STDERR_FILENO);
      close(fds[0]);
      close(fds[1]);
      std::vector<std::string> args = {test::edgeslamBinary().string()};
      args.insert(args.end(), arguments.begin(), arguments.end());
      std::vector<char*> argv;
      for (auto& a : args) argv.push_back(a.data());
      argv.push_back(nullptr);
      execv(argv[0], argv.data());
      _exit(127);
    }
    close(fds[1]);
    fd_ = fds[0];
  }
  ~BackgroundRun() {
    if (pid_ > 0 && exit_code_ < 0) {
      kill(pid_, SIGKILL);
      waitpid(pid_, nullptr, 0);
    }
    if (fd_ >= 0) close(fd_);
  }

  // Reads output until it holds `text` (true) or `patience` passes. (No std::regex: GCC 12's
  // -Wmaybe-uninitialized fires inside <regex> in the sanitizer build.)
  bool waitFor(const std::string& text, std::chrono::seconds patience) {
    const auto deadline = std::chrono::steady_clock::now() + patience;
    while (output_.find(text) == std::string::npos && std::chrono::steady_clock::now() < deadline) {
      if (!readSome(100)) break;
    }
    return output_.find(text) != std::string::npos;
  }
  // Keeps draining the output (so the run never blocks on a full pipe) for about `duration`.
  void drain(std::chrono::milliseconds duration) {
    const auto deadline = std::chrono::steady_clock::now() + duration;
    while (std::chrono::steady_clock::now() < deadline && readSome(20)) {
    }
  }
  void interrupt() { kill(pid_, SIGINT); }
  int wait(std::chrono::seconds patience) {
    const auto deadline = std::chrono::steady_clock::now() + patience;
    while (std::chrono::steady_clock::now() < deadline) {
      readSome(50);
      int status = 0;
      if (waitpid(pid_, &status, WNOHANG) == pid_) {
        while (readSome(0)) {
        }
        exit_code_ = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
        return exit_code_;
      }
    }
    return -1;
  }
  const std::string& output() const { return output_; }

 private:
  // False at the end of the output.
  bool readSome(int timeout_ms) {
    pollfd p{fd_, POLLIN, 0};
    if (poll(&p, 1, timeout_ms) <= 0) return true;
    char buffer[4096];
    const ssize_t n = read(fd_, buffer, sizeof(buffer));
    if (n <= 0) return false;
    output_.append(buffer, static_cast<std::size_t>(n));
    return true;
  }

  pid_t pid_ = -1;
  int fd_ = -1;
  int exit_code_ = -1;
  std::string output_;
};

TEST(ViewerCommand, ServesTheRunAndLingersUntilInterrupted) {
  EDGESLAM_REQUIRE_SHARED(kDataset);
  BackgroundRun run({"run", "--dataset", test::sharedPath(kDataset).string(), "--sensor", "rgbd",
                     "--mode", "local", "--max-frames", "60", "--vocab", "none", "--viewer", "0",
                     "--viewer-linger", "600"});
  const std::string url_prefix = "viewer: http://127.0.0.1:";
  ASSERT_TRUE(run.waitFor(url_prefix, 120s)) << run.output();
  const int port =
      std::atoi(run.output().c_str() + run.output().find(url_prefix) + url_prefix.size());
  ASSERT_GT(port, 0) << run.output();
  httplib::Client client("127.0.0.1", port);
  client.set_connection_timeout(10);
  client.set_read_timeout(30);
  // Wait for the run to end (the viewer lingers then), asking the state meanwhile.
  nlohmann::json state;
  const auto deadline = std::chrono::steady_clock::now() + 180s;
  while (std::chrono::steady_clock::now() < deadline) {
    const auto res = client.Get("/api/state");
    ASSERT_TRUE(res) << httplib::to_string(res.error()) << "\n" << run.output();
    ASSERT_EQ(res->status, 200);
    state = nlohmann::json::parse(res->body);
    if (state["status"]["finished"].get<bool>()) break;
    run.drain(200ms);
  }
  ASSERT_TRUE(state["status"]["finished"].get<bool>()) << run.output();
  EXPECT_EQ(state["status"]["frame"], 60);
  EXPECT_EQ(state["status"]["frames_total"], 60);
  EXPECT_EQ(state["status"]["mode"], "local");
  EXPECT_EQ(state["status"]["sensor"], "rgbd");
  EXPECT_GT(state["status"]["keyframes"].get<int>(), 0);
  EXPECT_GE(state["trajectory"].size(), 3u * 50u);  // the tracked frames
  EXPECT_EQ(state["trajectory"].size() % 3, 0u);
  EXPECT_EQ(state["ground_truth"].size(), 3u * 60u);  // 7-Scenes has poses
  EXPECT_FALSE(state["camera"].is_null());
  EXPECT_FALSE(state["keyframes"].empty());
  EXPECT_FALSE(state["points"].empty());
  const auto page = client.Get("/");
  ASSERT_TRUE(page);
  EXPECT_EQ(page->status, 200);
  EXPECT_TRUE(run.waitFor("serving the final map", 60s)) << run.output();
  run.interrupt();
  EXPECT_EQ(run.wait(60s), 0) << run.output();
  EXPECT_NE(run.output().find("viewer: stopped (interrupted)"), std::string::npos) << run.output();
}

TEST(ViewerCommand, PortOutOfRangeIsAClearError) {
  for (const char* port : {"70000", "-5", "http"}) {
    const auto r = test::runEdgeslam("run --dataset /nonexistent --viewer " + std::string(port));
    EXPECT_NE(r.exit_code, 0) << port;
    EXPECT_NE(r.output.find("--viewer"), std::string::npos) << port << ": " << r.output;
  }
}

TEST(ViewerCommand, PortInUseIsAClearErrorBeforeAnyFrame) {
  EDGESLAM_REQUIRE_SHARED(kDataset);
  httplib::Server blocker;
  const int port = blocker.bind_to_any_port("127.0.0.1");
  ASSERT_GT(port, 0);
  const auto r = test::runEdgeslam("run --dataset " + test::sharedPath(kDataset).string() +
                                   " --mode local --max-frames 5 --vocab none --viewer " +
                                   std::to_string(port));
  EXPECT_NE(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("cannot listen on 127.0.0.1:" + std::to_string(port)), std::string::npos)
      << r.output;
  EXPECT_EQ(r.output.find("Summary"), std::string::npos) << r.output;
}

}  // namespace
}  // namespace edgeslam
