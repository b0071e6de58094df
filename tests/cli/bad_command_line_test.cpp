// Runs the real `edgeslam` binary with bad command lines: missing, garbage and contradictory
// arguments (exit 2), and unreadable, empty or inconsistent inputs (exit 1). Every failure must
// be one line on stderr, quick, and never a crash or a hang.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "support/shared_data.h"

namespace edgeslam {
namespace {

namespace fs = std::filesystem;

constexpr int kUsage = 2;
constexpr int kRuntime = 1;
constexpr double kMaxSeconds = 30.0;

struct BadInvocation {
  std::string arguments;
  int expected_exit;
};

struct Outcome {
  int exit_code = -1;  // -1: killed by a signal (a crash)
  std::string stderr_text;
  double seconds = 0.0;
};

std::string readAll(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

void writeFile(const fs::path& path, const std::string& content) {
  std::ofstream(path, std::ios::binary) << content;
}

// A scratch folder with the bad inputs, made once for the whole sweep.
class BadInputs {
 public:
  BadInputs()
      : root_(fs::temp_directory_path() / ("edgeslam_bad_cli_" + std::to_string(getpid()))) {
    fs::remove_all(root_);
    fs::create_directories(root_ / "empty_dir");
    fs::create_directories(root_ / "out");
    writeFile(path("empty.txt"), "");
    writeFile(path("garbage.bin"),
              std::string("\x89\x01garbage\xff\xfe not a file of any kind\n", 33));
    writeFile(path("garbage.yaml"), "width: [640\nfx: }}}\n");
    writeFile(path("negative_focal.yaml"),
              "width: 640\nheight: 480\nfx: -585\nfy: 585\ncx: 320\ncy: 240\n");
    writeFile(path("unknown_key.yaml"),
              "width: 640\nheight: 480\nfx: 585\nfy: 585\ncx: 320\ncy: 240\nlens: fisheye\n");
    writeFile(path("gt.txt"),
              "1.0 0 0 0 0 0 0 1\n2.0 1 0 0 0 0 0 1\n3.0 2 0 0 0 0 0 1\n"
              "4.0 3 0 0 0 0 0 1\n");
    writeFile(path("est_later.txt"),
              "100.0 0 0 0 0 0 0 1\n101.0 1 0 0 0 0 0 1\n"
              "102.0 2 0 0 0 0 0 1\n103.0 3 0 0 0 0 0 1\n");
    writeFile(path("garbage_trajectory.txt"), "this is not\na trajectory 1 2 3\n");
    writeFile(path("garbage.vocab"), std::string(4096, '\x5a'));
    writeFile(path("garbage.png"), "\x89PNG\r\n\x1a\n not really a png");
    writeFile(path("garbage_trace.csv"), "time,up\nnope,nope\n");
    // An image folder whose images are not the size its camera file declares.
    fs::create_directories(root_ / "small_images");
    const fs::path tum_image = test::sharedPath("datasets/tum-fr2desk-20/rgb");
    writeFile(path("small_images/camera.yaml"),
              "width: 320\nheight: 240\nfx: 300\nfy: 300\ncx: 160\ncy: 120\n");
    if (fs::exists(tum_image)) {
      int copied = 0;
      for (const auto& entry : fs::directory_iterator(tum_image)) {
        if (copied++ == 3) break;
        fs::copy_file(entry.path(), root_ / "small_images" / entry.path().filename());
      }
    }
  }
  ~BadInputs() { fs::remove_all(root_); }
  BadInputs(const BadInputs&) = delete;
  BadInputs& operator=(const BadInputs&) = delete;

  std::string path(const std::string& name) const { return (root_ / name).string(); }

 private:
  fs::path root_;
};

Outcome runEdgeslam(const std::string& arguments, const fs::path& scratch) {
  const fs::path err = scratch / "stderr.txt";
  // `timeout` turns a hang into a failure (exit 124 or 137) instead of a stuck test.
  const std::string command = "timeout -k 5 " + std::to_string(static_cast<int>(kMaxSeconds) + 10) +
                              " " + test::edgeslamBinary().string() + " " + arguments +
                              " </dev/null >/dev/null 2>" + err.string();
  const auto start = std::chrono::steady_clock::now();
  const int status = std::system(command.c_str());
  Outcome outcome;
  outcome.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  outcome.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  outcome.stderr_text = readAll(err);
  return outcome;
}

bool isOneLine(std::string text) {
  while (!text.empty() && text.back() == '\n') text.pop_back();
  return !text.empty() && text.find('\n') == std::string::npos;
}

std::vector<BadInvocation> sweep(const BadInputs& in) {
  const std::string tum = test::sharedPath("datasets/tum-fr2desk-20").string();
  const std::string gt = in.path("gt.txt");
  const std::string out = " --out " + in.path("out/run");
  return {
      // The root command.
      {"", kUsage},
      {"bogus", kUsage},
      {"--log-level loud dataset info --dataset " + tum, kUsage},
      {"--no-such-flag", kUsage},
      // run
      {"run", kUsage},
      {"run --dataset", kUsage},
      {"run --dataset " + tum + " --mode bogus", kUsage},
      {"run --dataset " + tum + " --features -3", kUsage},
      {"run --dataset " + tum + " --features many", kUsage},
      {"run --dataset " + tum + " --frames 10-5", kUsage},
      {"run --dataset " + tum + " --frames ten", kUsage},
      {"run --dataset " + tum + " --frames 5-500", kUsage},  // past the dataset's 20 frames
      {"run --dataset " + tum + " --realtime --fast", kUsage},
      {"run --dataset " + tum + " --deterministic --realtime", kUsage},
      {"run --dataset " + tum + " --deterministic --mode edge", kUsage},
      {"run --dataset " + tum + " --format tiff", kUsage},
      {"run --dataset " + tum + " --sensor lidar", kUsage},
      {"run --dataset " + tum + " --link carrier-pigeon", kUsage},
      {"run --dataset " + tum + " --adapt maybe", kUsage},
      {"run --dataset " + tum + " --viewer 70000", kUsage},
      {"run --dataset " + tum + " --alpha 2", kUsage},
      {"run --dataset " + tum + " --refine-intrinsics zoom", kUsage},
      {"run --dataset " + tum + " --camera " + in.path("missing.yaml"), kUsage},
      {"run --dataset " + tum + " --no-such-flag", kUsage},
      {"run --dataset " + tum + " extra-positional", kUsage},
      {"run --dataset " + in.path("missing") + out, kRuntime},
      {"run --dataset " + in.path("empty_dir") + out, kRuntime},
      {"run --dataset " + in.path("empty.txt") + out, kRuntime},
      {"run --dataset " + in.path("garbage.bin") + out, kRuntime},
      {"run --dataset " + tum + " --camera " + in.path("garbage.yaml") + out, kRuntime},
      {"run --dataset " + tum + " --camera " + in.path("negative_focal.yaml") + out, kRuntime},
      {"run --dataset " + tum + " --camera " + in.path("unknown_key.yaml") + out, kRuntime},
      {"run --dataset " + tum + " --camera " + in.path("empty.txt") + out, kRuntime},
      {"run --dataset " + tum + " --vocab " + in.path("garbage.vocab") + out, kRuntime},
      {"run --dataset " + tum + " --vocab " + in.path("missing.vocab") + out, kRuntime},
      {"run --dataset " + tum + " --sensor rgbd" + out, kRuntime},
      {"run --dataset " + in.path("small_images") + " --format images --camera " +
           in.path("small_images/camera.yaml") + " --mode local" + out,
       kRuntime},
      // client
      {"client --dataset " + tum, kUsage},
      {"client --dataset " + tum + " --server 127.0.0.1:1 --mode local", kUsage},
      {"client --dataset " + in.path("empty_dir") + " --server 127.0.0.1:1" + out, kRuntime},
      // server
      {"server --listen", kUsage},
      {"server --status-every often", kUsage},
      {"server --semantic perhaps", kUsage},
      {"server --listen 127.0.0.1:0 --vocab " + in.path("garbage.vocab"), kRuntime},
      {"server --listen 127.0.0.1:99999 --vocab none --semantic off", kUsage},
      {"server --listen 127.0.0.1:port --vocab none --semantic off", kUsage},
      {"server --listen 127.0.0.1 --vocab none --semantic off", kUsage},
      {"server --listen 0.0.0.0:0 --vocab none --semantic off", kUsage},  // no TLS off loopback
      {"server --tls-cert " + in.path("garbage.yaml"), kUsage},           // --tls-key missing
      {"server --listen 127.0.0.1:0 --tls-cert " + in.path("garbage.yaml") + " --tls-key " +
           in.path("garbage.yaml") + " --vocab none --semantic off",
       kRuntime},  // not PEM
      {"server --listen 127.0.0.1:0 --auth-tokens " + in.path("empty.txt") +
           " --vocab none --semantic off",
       kRuntime},
      {"client --dataset " + tum + " --server 127.0.0.1:1 --tls-ca " + in.path("missing.pem") + out,
       kRuntime},
      // linkem
      {"linkem --listen 127.0.0.1:0", kUsage},
      {"linkem --listen 127.0.0.1:0 --target 127.0.0.1:1 --profile dialup", kUsage},
      {"linkem --listen 127.0.0.1:0 --target 127.0.0.1:1 --interval -1", kUsage},
      {"linkem --listen 127.0.0.1:0 --target 127.0.0.1:1 --loss lots", kUsage},
      {"linkem --listen 127.0.0.1:0 --target 127.0.0.1:1 --trace " + in.path("garbage_trace.csv"),
       kRuntime},
      {"linkem --listen 127.0.0.1:0 --target 127.0.0.1:1 --trace " + in.path("missing.csv"),
       kRuntime},
      {"linkem --listen 999.0.0.1:0 --target 127.0.0.1:1", kRuntime},
      // vocab
      {"vocab", kUsage},
      {"vocab train --images " + in.path("empty_dir"), kUsage},
      {"vocab train --images " + tum + " --out x.vocab --features -3", kUsage},
      {"vocab train --images " + tum + " --out x.vocab --k 1", kUsage},
      {"vocab train --images " + tum + " --out x.vocab --weighting loud", kUsage},
      {"vocab info", kUsage},
      {"vocab train --images " + in.path("empty_dir") + " --out " + in.path("out/x.vocab"),
       kRuntime},
      {"vocab train --images " + in.path("missing") + " --out " + in.path("out/x.vocab"), kRuntime},
      {"vocab info " + in.path("garbage.vocab"), kRuntime},
      {"vocab info " + in.path("empty.txt"), kRuntime},
      {"vocab info " + in.path("missing.vocab"), kRuntime},
      // segment
      {"segment", kUsage},
      {"segment --image " + in.path("garbage.png") + " --images " + in.path("empty_dir"), kUsage},
      {"segment --image " + in.path("garbage.png") + " --nm 2", kUsage},
      {"segment --image " + in.path("garbage.png") + " --backend magic", kUsage},
      {"segment --image " + in.path("garbage.png"), kRuntime},
      {"segment --image " + in.path("missing.png"), kRuntime},
      {"segment --images " + in.path("empty_dir"), kRuntime},
      {"segment --truth " + in.path("empty_dir"), kRuntime},
      // synth-dynamic
      {"synth-dynamic --dataset " + tum, kUsage},
      {"synth-dynamic --dataset " + tum + " --out " + in.path("out/dyn") + " --num-people 9",
       kUsage},
      {"synth-dynamic --dataset " + in.path("empty_dir") + " --out " + in.path("out/dyn"),
       kRuntime},
      {"synth-dynamic --dataset " + tum + " --out " + in.path("out/dyn2") + " --frames 900-999",
       kRuntime},
      // dataset
      {"dataset", kUsage},
      {"dataset info", kUsage},
      {"dataset info --dataset " + tum + " --format tiff", kUsage},
      {"dataset info --dataset " + in.path("missing"), kRuntime},
      {"dataset info --dataset " + in.path("empty_dir"), kRuntime},
      {"dataset info --dataset " + in.path("empty.txt"), kRuntime},
      {"dataset info --dataset " + tum + " --camera " + in.path("garbage.yaml"), kRuntime},
      {"dataset info --dataset " + tum + " --camera " + in.path("negative_focal.yaml"), kRuntime},
      // eval
      {"eval", kUsage},
      {"eval ate --gt " + gt, kUsage},
      {"eval ate --gt " + gt + " --est " + gt + " --align rotate", kUsage},
      {"eval ate --gt " + gt + " --est " + gt + " --max-dt -1", kUsage},
      {"eval rpe --gt " + gt + " --est " + gt + " --delta -1", kUsage},
      {"eval rpe --gt " + gt + " --est " + gt + " --delta-unit parsecs", kUsage},
      {"eval ate --gt " + gt + " --est " + in.path("est_later.txt"), kRuntime},
      {"eval ate --gt " + in.path("empty.txt") + " --est " + gt, kRuntime},
      {"eval ate --gt " + gt + " --est " + in.path("missing.txt"), kRuntime},
      {"eval ate --gt " + gt + " --est " + in.path("garbage_trajectory.txt"), kRuntime},
      {"eval rpe --gt " + gt + " --est " + in.path("est_later.txt"), kRuntime},
      {"eval kitti --gt " + gt + " --est " + in.path("garbage.bin"), kRuntime},
      {"eval kitti --gt " + gt + " --est " + gt + " --times " + in.path("garbage.bin"), kRuntime},
  };
}

TEST(BadCommandLine, EveryCommandFailsWithOneLineAndTheRightExitCode) {
  EDGESLAM_REQUIRE_SHARED("datasets/tum-fr2desk-20");
  const BadInputs inputs;
  const std::vector<BadInvocation> cases = sweep(inputs);
  std::size_t failures = 0;
  for (const BadInvocation& c : cases) {
    const Outcome o = runEdgeslam(c.arguments, inputs.path("out"));
    const bool ok =
        o.exit_code == c.expected_exit && isOneLine(o.stderr_text) && o.seconds < kMaxSeconds;
    if (!ok) ++failures;
    EXPECT_TRUE(ok) << "edgeslam " << c.arguments << "\n  exit " << o.exit_code << " (expected "
                    << c.expected_exit << ") after " << o.seconds << " s, stderr:\n"
                    << o.stderr_text;
  }
  std::cout << cases.size() << " bad invocations, " << failures << " failed\n";
  EXPECT_GE(cases.size(), 80U);
}

}  // namespace
}  // namespace edgeslam
