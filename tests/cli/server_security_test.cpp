// `edgeslam server` and `edgeslam client` as two real processes over TLS with a client token: a
// self-signed certificate made with the openssl command, a token file, the right token let in,
// a wrong one or a missing CA refused, and an address off loopback refused without TLS.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "support/shared_data.h"

extern char** environ;

namespace edgeslam {
namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;

constexpr const char* kToken = "test-token-0123456789abcdef";

std::string readAll(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

struct Outcome {
  int exit_code = -1;
  std::string stderr_text;
};

Outcome run(const std::string& arguments, const fs::path& scratch) {
  const fs::path err = scratch / "stderr.txt";
  const std::string command = "timeout -k 5 120 " + test::edgeslamBinary().string() + " " +
                              arguments + " </dev/null >/dev/null 2>" + err.string();
  const int status = std::system(command.c_str());
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, readAll(err)};
}

// A server process with its stdout and stderr in `log`; SIGTERM and reaped on destruction.
class ServerProcess {
 public:
  ServerProcess(const std::vector<std::string>& arguments, const fs::path& log) : log_(log) {
    std::vector<std::string> argv_storage{test::edgeslamBinary().string(), "server"};
    argv_storage.insert(argv_storage.end(), arguments.begin(), arguments.end());
    std::vector<char*> argv;
    for (std::string& a : argv_storage) argv.push_back(a.data());
    argv.push_back(nullptr);
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_addopen(&actions, 1, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    posix_spawn_file_actions_adddup2(&actions, 1, 2);
    if (posix_spawn(&pid_, argv[0], &actions, nullptr, argv.data(), environ) != 0) pid_ = -1;
    posix_spawn_file_actions_destroy(&actions);
  }
  ~ServerProcess() { stop(); }
  ServerProcess(const ServerProcess&) = delete;
  ServerProcess& operator=(const ServerProcess&) = delete;

  // The port from the "listening on HOST:PORT" line, or 0 when the server did not get there.
  int waitForPort(std::chrono::seconds timeout = 60s) {
    const std::regex listening("listening on [^ ]+:([0-9]+)");
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    while (std::chrono::steady_clock::now() < deadline) {
      std::smatch match;
      const std::string log = readAll(log_);
      if (std::regex_search(log, match, listening)) return std::stoi(match[1]);
      int status = 0;
      if (pid_ <= 0 || waitpid(pid_, &status, WNOHANG) == pid_) {
        pid_ = -1;
        return 0;
      }
      std::this_thread::sleep_for(100ms);
    }
    return 0;
  }

  int stop() {
    if (pid_ <= 0) return -1;
    kill(pid_, SIGTERM);
    int status = 0;
    waitpid(pid_, &status, 0);
    pid_ = -1;
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  }

 private:
  pid_t pid_ = -1;
  fs::path log_;
};

class ServerSecurity : public ::testing::Test {
 protected:
  void SetUp() override {
    if (std::system("openssl version >/dev/null 2>&1") != 0) {
      GTEST_SKIP() << "no openssl command (Debian package openssl; scripts/deps.sh installs it)";
    }
    dir_ = fs::temp_directory_path() / ("edgeslam_tls_" + std::to_string(getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    const std::string openssl =
        "openssl req -x509 -newkey ec -pkeyopt ec_paramgen_curve:prime256v1 -nodes -days 2 "
        "-subj /CN=localhost -addext subjectAltName=IP:127.0.0.1,DNS:localhost -keyout " +
        path("key.pem") + " -out " + path("cert.pem") + " >/dev/null 2>&1";
    ASSERT_EQ(std::system(openssl.c_str()), 0) << openssl;
    std::ofstream(dir_ / "tokens.txt") << "# test clients\n" << kToken << "\n";
  }
  void TearDown() override {
    if (!dir_.empty()) fs::remove_all(dir_);
  }

  std::string path(const std::string& name) const { return (dir_ / name).string(); }

  std::vector<std::string> tlsServerArguments(const std::string& listen) const {
    return {"--listen",       listen,
            "--tls-cert",     path("cert.pem"),
            "--tls-key",      path("key.pem"),
            "--auth-tokens",  path("tokens.txt"),
            "--vocab",        "none",
            "--semantic",     "off",
            "--status-every", "0"};
  }

  fs::path dir_;
};

TEST_F(ServerSecurity, ClientOverTlsWithItsToken) {
  EDGESLAM_REQUIRE_SHARED("datasets/tum-fr2desk-20");
  ServerProcess server(tlsServerArguments("127.0.0.1:0"), dir_ / "server.log");
  const int port = server.waitForPort();
  ASSERT_GT(port, 0) << readAll(dir_ / "server.log");
  EXPECT_NE(readAll(dir_ / "server.log").find("TLS, 1 client token(s)"), std::string::npos)
      << readAll(dir_ / "server.log");
  const std::string client = "client --server 127.0.0.1:" + std::to_string(port) + " --dataset " +
                             test::sharedPath("datasets/tum-fr2desk-20").string() +
                             " --mode edge --vocab none --max-frames 12";

  const Outcome ok =
      run(client + " --tls-ca " + path("cert.pem") + " --token " + kToken + " --out " + path("out"),
          dir_);
  EXPECT_EQ(ok.exit_code, 0) << ok.stderr_text;
  EXPECT_TRUE(fs::exists(dir_ / "out" / "metrics.json"));

  const Outcome wrong_token =
      run(client + " --tls-ca " + path("cert.pem") + " --token wrong-0123456789abcdef", dir_);
  EXPECT_EQ(wrong_token.exit_code, 1) << wrong_token.stderr_text;
  EXPECT_NE(wrong_token.stderr_text.find("not known to this edge server"), std::string::npos)
      << wrong_token.stderr_text;

  const Outcome no_token = run(client + " --tls-ca " + path("cert.pem"), dir_);
  EXPECT_EQ(no_token.exit_code, 1) << no_token.stderr_text;
  EXPECT_NE(no_token.stderr_text.find("wants a client token"), std::string::npos)
      << no_token.stderr_text;

  // The token from the environment, as the docs recommend.
  setenv("EDGESLAM_TOKEN", kToken, 1);
  const Outcome env_token = run(client + " --tls-ca " + path("cert.pem"), dir_);
  unsetenv("EDGESLAM_TOKEN");
  EXPECT_EQ(env_token.exit_code, 0) << env_token.stderr_text;

  // Plaintext against a TLS server: no connection.
  const Outcome plaintext = run(client + " --token " + kToken, dir_);
  EXPECT_EQ(plaintext.exit_code, 1) << plaintext.stderr_text;
  EXPECT_NE(plaintext.stderr_text.find("not reachable"), std::string::npos)
      << plaintext.stderr_text;
  EXPECT_EQ(server.stop(), 0);
}

TEST_F(ServerSecurity, OffLoopbackTheServerWantsTlsAndTokens) {
  const Outcome open_server = run("server --listen 0.0.0.0:0 --vocab none --semantic off", dir_);
  EXPECT_EQ(open_server.exit_code, 2) << open_server.stderr_text;
  EXPECT_NE(open_server.stderr_text.find("--insecure"), std::string::npos)
      << open_server.stderr_text;
  const Outcome tls_only = run("server --listen 0.0.0.0:0 --vocab none --semantic off --tls-cert " +
                                   path("cert.pem") + " --tls-key " + path("key.pem"),
                               dir_);
  EXPECT_EQ(tls_only.exit_code, 2) << tls_only.stderr_text;
  const Outcome key_missing =
      run("server --listen 127.0.0.1:0 --tls-cert " + path("cert.pem"), dir_);
  EXPECT_EQ(key_missing.exit_code, 2) << key_missing.stderr_text;
  std::ofstream(dir_ / "short_tokens.txt") << "short\n";
  const Outcome bad_tokens =
      run("server --listen 0.0.0.0:0 --vocab none --semantic off "
          "--tls-cert " +
              path("cert.pem") + " --tls-key " + path("key.pem") + " --auth-tokens " +
              path("short_tokens.txt"),
          dir_);
  EXPECT_EQ(bad_tokens.exit_code, 1) << bad_tokens.stderr_text;

  {
    ServerProcess secured(tlsServerArguments("0.0.0.0:0"), dir_ / "secured.log");
    EXPECT_GT(secured.waitForPort(), 0) << readAll(dir_ / "secured.log");
  }
  ServerProcess insecure({"--listen", "0.0.0.0:0", "--insecure", "--vocab", "none", "--semantic",
                          "off", "--status-every", "0"},
                         dir_ / "insecure.log");
  EXPECT_GT(insecure.waitForPort(), 0) << readAll(dir_ / "insecure.log");
  EXPECT_NE(readAll(dir_ / "insecure.log").find("without TLS or tokens"), std::string::npos);
}

}  // namespace
}  // namespace edgeslam
