// The map store as a user meets it: an edge run writes its map into a store folder; `edgeslam map`
// lists, describes, exports and removes it; a killed process leaves a store that opens; a damaged
// store is one line naming the file.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <string>
#include <thread>

#include "support/edgeslam_command.h"
#include "support/fresh_temp_dir.h"
#include "support/shared_data.h"

namespace edgeslam {
namespace {

constexpr const char* kSequence = "datasets/7scenes-redkitchen-1000";

std::filesystem::path tempDir(const std::string& name) {
  return test::freshTempDir("map_command_" + name);
}

std::size_t dataLineCount(const std::filesystem::path& file) {
  std::ifstream in(file);
  std::size_t n = 0;
  for (std::string line; std::getline(in, line);) {
    if (!line.empty() && line[0] != '#') ++n;
  }
  return n;
}

std::string readBytes(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

nlohmann::json jsonOf(const test::CommandResult& r) {
  return nlohmann::json::parse(r.output, nullptr, false);
}

TEST(MapCommand, EdgeRunWritesAMapThatListsDescribesExportsAndRemoves) {
  EDGESLAM_REQUIRE_SHARED(kSequence);
  const auto store = tempDir("store");
  const auto out = tempDir("out");
  const std::string maps = " --maps " + store.string();
  const auto run = test::runEdgeslam("run --dataset " + test::sharedPath(kSequence).string() +
                                     " --mode edge --sensor rgbd --max-frames 150 --vocab none" +
                                     maps + " --map kitchen --out " + out.string());
  ASSERT_EQ(run.exit_code, 0) << run.output;
  std::ifstream metrics_file(out / "metrics.json");
  const auto metrics = nlohmann::json::parse(metrics_file);
  ASSERT_TRUE(metrics.contains("store")) << metrics.dump();
  const auto& written = metrics["store"];
  EXPECT_EQ(written["map"], "kitchen");
  EXPECT_EQ(written["failures"], 0);
  EXPECT_GE(written["keyframes_written"].get<int>(), written["keyframes"].get<int>());
  EXPECT_EQ(written["keyframes"], metrics["keyframes"]);
  EXPECT_GT(written["bytes_per_keyframe"].get<int>(), 10000);

  const auto info = test::runEdgeslam("map info kitchen --json --load" + maps, false);
  ASSERT_EQ(info.exit_code, 0) << info.output;
  const auto m = jsonOf(info);
  ASSERT_TRUE(m.is_object()) << info.output;
  const int keyframes = m["keyframes"].get<int>();
  const int points = m["points"].get<int>();
  EXPECT_GE(keyframes, 5);
  EXPECT_EQ(keyframes, metrics["keyframes"].get<int>());
  EXPECT_GT(points, 20 * keyframes);
  EXPECT_EQ(m["sessions"], 1);
  EXPECT_GT(m["bytes"].get<double>(), 0.0);
  EXPECT_EQ(m["load"]["keyframes"], keyframes);
  EXPECT_EQ(m["load"]["points"], points);

  const auto list = test::runEdgeslam("map list --json" + maps, false);
  ASSERT_EQ(list.exit_code, 0) << list.output;
  EXPECT_EQ(jsonOf(list)["maps"][0]["name"], "kitchen");

  // TUM: the edge's keyframes, where the run's own final keyframe poses say they are.
  ASSERT_EQ(test::runEdgeslam("map export kitchen --format tum --out " +
                              (out / "map.tum").string() + maps)
                .exit_code,
            0);
  EXPECT_EQ(dataLineCount(out / "map.tum"), static_cast<std::size_t>(keyframes));
  const auto ate =
      test::runEdgeslam("eval ate --gt " + (out / "keyframes.tum").string() + " --est " +
                            (out / "map.tum").string() + " --align none --json",
                        false);
  ASSERT_EQ(ate.exit_code, 0) << ate.output;
  EXPECT_LT(jsonOf(ate)["rmse_m"].get<double>(), 0.01) << ate.output;
  EXPECT_GE(jsonOf(ate)["pairs"].get<int>(), keyframes - 2) << ate.output;

  ASSERT_EQ(test::runEdgeslam("map export kitchen --format ply --out " +
                              (out / "map.ply").string() + maps)
                .exit_code,
            0);
  const std::string ply = readBytes(out / "map.ply");
  EXPECT_EQ(ply.rfind("ply\n", 0), 0u);
  EXPECT_NE(ply.find("element vertex " + std::to_string(points) + "\n"), std::string::npos);

  ASSERT_EQ(test::runEdgeslam("map export kitchen --format colmap --out " +
                              (out / "colmap").string() + maps)
                .exit_code,
            0);
  EXPECT_EQ(dataLineCount(out / "colmap" / "cameras.txt"), 1u);
  EXPECT_EQ(dataLineCount(out / "colmap" / "images.txt"), 2u * keyframes);
  EXPECT_EQ(dataLineCount(out / "colmap" / "points3D.txt"), static_cast<std::size_t>(points));

  // Export again from the stored map (reloaded): the same bytes.
  ASSERT_EQ(test::runEdgeslam("map export kitchen --format colmap --out " +
                              (out / "colmap2").string() + maps)
                .exit_code,
            0);
  for (const char* file : {"cameras.txt", "images.txt", "points3D.txt"}) {
    EXPECT_EQ(readBytes(out / "colmap" / file), readBytes(out / "colmap2" / file)) << file;
  }

  const auto rm = test::runEdgeslam("map rm kitchen" + maps);
  EXPECT_EQ(rm.exit_code, 0) << rm.output;
  const auto gone = test::runEdgeslam("map info kitchen" + maps);
  EXPECT_EQ(gone.exit_code, 1) << gone.output;
  EXPECT_NE(gone.output.find("no map 'kitchen'"), std::string::npos) << gone.output;
  EXPECT_NE(gone.output.find((store / "maps.sqlite").string()), std::string::npos);
  std::filesystem::remove_all(store);
  std::filesystem::remove_all(out);
}

TEST(MapCommand, KilledRunLeavesAStoreThatOpens) {
  EDGESLAM_REQUIRE_SHARED(kSequence);
  const auto store = tempDir("killed");
  const std::string command = test::edgeslamBinary().string() + " run --dataset " +
                              test::sharedPath(kSequence).string() +
                              " --mode edge --sensor rgbd --realtime --vocab none --maps " +
                              store.string() + " --map killed > /dev/null 2>&1 & echo $!";
  FILE* pipe = ::popen(command.c_str(), "r");
  ASSERT_NE(pipe, nullptr);
  int pid = 0;
  ASSERT_EQ(std::fscanf(pipe, "%d", &pid), 1);
  ::pclose(pipe);
  // Well into the run (30 fps: ~200 frames), while batches are being written; readers look on.
  std::this_thread::sleep_for(std::chrono::seconds(6));
  const auto live = test::runEdgeslam("map list --json --maps " + store.string(), false);
  EXPECT_EQ(live.exit_code, 0) << live.output;
  EXPECT_EQ(jsonOf(live)["maps"][0]["name"], "killed") << live.output;
  const auto locked = test::runEdgeslam("map rm killed --maps " + store.string());
  EXPECT_EQ(locked.exit_code, 1) << locked.output;
  EXPECT_NE(locked.output.find("locked"), std::string::npos) << locked.output;
  std::this_thread::sleep_for(std::chrono::seconds(2));
  ASSERT_EQ(::kill(pid, SIGKILL), 0);
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  const auto info =
      test::runEdgeslam("map info killed --json --load --maps " + store.string(), false);
  ASSERT_EQ(info.exit_code, 0) << info.output;
  const auto m = jsonOf(info);
  EXPECT_GE(m["keyframes"].get<int>(), 3) << info.output;
  EXPECT_EQ(m["load"]["keyframes"], m["keyframes"]);
  // The next writer takes the store over (the dead process's lock went with it).
  const auto again = test::runEdgeslam("run --dataset " + test::sharedPath(kSequence).string() +
                                       " --mode edge --sensor rgbd --max-frames 30 --vocab none " +
                                       "--maps " + store.string() + " --map killed");
  EXPECT_EQ(again.exit_code, 0) << again.output;
  const auto after =
      jsonOf(test::runEdgeslam("map info killed --json --maps " + store.string(), false));
  // The second run resumed the stored session (docs/map_store.md, Restart and resync) and wrote
  // its keyframes into it.
  EXPECT_EQ(after["sessions"], 1);
  EXPECT_GT(after["keyframes"].get<int>(), m["keyframes"].get<int>()) << after.dump();
  std::filesystem::remove_all(store);
}

int startInBackground(const std::string& arguments) {
  const std::string command =
      test::edgeslamBinary().string() + " " + arguments + " > /dev/null 2>&1 & echo $!";
  FILE* pipe = ::popen(command.c_str(), "r");
  int pid = 0;
  if (pipe == nullptr || std::fscanf(pipe, "%d", &pid) != 1) pid = 0;
  if (pipe != nullptr) ::pclose(pipe);
  return pid;
}

// Two processes: the server's store is written while the client maps, and a server killed with
// SIGKILL leaves it openable, holding what was mapped, for the next server.
TEST(MapCommand, KilledServerLeavesItsMapsForTheNextOne) {
  EDGESLAM_REQUIRE_SHARED(kSequence);
  const auto store = tempDir("server");
  const int port = 48000 + static_cast<int>(::getpid() % 1000);
  const std::string serve = "server --listen 127.0.0.1:" + std::to_string(port) +
                            " --status-every 0 --vocab none --semantic off --maps " +
                            store.string();
  const int server = startInBackground(serve);
  ASSERT_GT(server, 0);
  std::this_thread::sleep_for(std::chrono::milliseconds(800));
  const int client = startInBackground("client --server 127.0.0.1:" + std::to_string(port) +
                                       " --dataset " + test::sharedPath(kSequence).string() +
                                       " --sensor rgbd --realtime --vocab none --map office");
  ASSERT_GT(client, 0);
  std::this_thread::sleep_for(std::chrono::seconds(8));
  ASSERT_EQ(::kill(server, SIGKILL), 0);
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  ::kill(client, SIGKILL);
  const auto info =
      test::runEdgeslam("map info office --json --load --maps " + store.string(), false);
  ASSERT_EQ(info.exit_code, 0) << info.output;
  const auto m = jsonOf(info);
  EXPECT_GE(m["keyframes"].get<int>(), 3) << info.output;
  EXPECT_EQ(m["load"]["keyframes"], m["keyframes"]);
  // The next server opens the store (the lock went with the killed one) and serves on.
  const int next = startInBackground(serve);
  ASSERT_GT(next, 0);
  std::this_thread::sleep_for(std::chrono::milliseconds(800));
  const auto second = test::runEdgeslam("client --server 127.0.0.1:" + std::to_string(port) +
                                        " --dataset " + test::sharedPath(kSequence).string() +
                                        " --sensor rgbd --max-frames 30 --vocab none --map office");
  ::kill(next, SIGTERM);
  EXPECT_EQ(second.exit_code, 0) << second.output;
  std::this_thread::sleep_for(std::chrono::milliseconds(500));
  const auto after =
      jsonOf(test::runEdgeslam("map info office --json --maps " + store.string(), false));
  EXPECT_EQ(after["sessions"], 1) << after.dump();  // resumed
  EXPECT_GT(after["keyframes"].get<int>(), m["keyframes"].get<int>()) << after.dump();
  std::filesystem::remove_all(store);
}

TEST(MapCommand, DamagedStoreIsOneLineNamingTheFile) {
  const auto store = tempDir("damaged");
  std::filesystem::create_directories(store);
  const auto file = store / "maps.sqlite";
  std::ofstream(file) << std::string(10000, 'z');
  const std::string before = readBytes(file);
  const auto list = test::runEdgeslam("map list --maps " + store.string());
  EXPECT_EQ(list.exit_code, 1) << list.output;
  EXPECT_NE(list.output.find(file.string()), std::string::npos) << list.output;
  EXPECT_EQ(std::count(list.output.begin(), list.output.end(), '\n'), 1) << list.output;
  if (std::filesystem::exists(test::sharedPath(kSequence))) {
    const auto run =
        test::runEdgeslam("run --dataset " + test::sharedPath(kSequence).string() +
                          " --mode edge --max-frames 5 --vocab none --maps " + store.string());
    EXPECT_EQ(run.exit_code, 1) << run.output;
    EXPECT_NE(run.output.find(file.string()), std::string::npos) << run.output;
  }
  EXPECT_EQ(readBytes(file), before);
  const auto missing = test::runEdgeslam("map list --maps " + (store / "nothing").string());
  EXPECT_EQ(missing.exit_code, 1) << missing.output;
  // A usage error is not a store error (its exit code is the command line's, issue 23).
  const auto usage = test::runEdgeslam("map export x --maps " + store.string() + " --format");
  EXPECT_NE(usage.exit_code, 0) << usage.output;
  EXPECT_NE(usage.exit_code, 1) << usage.output;
  std::filesystem::remove_all(store);
}

// A store that cannot grow (the file size limit of the process, as a full disk would stop it):
// the run goes on and tracks every frame, the failed writes are counted and warned about, and the
// store still opens with what was written before.
TEST(MapCommand, StoreThatCannotGrowCostsTheRunNothingButIsReported) {
  EDGESLAM_REQUIRE_SHARED(kSequence);
  if (std::system("prlimit --version > /dev/null 2>&1") != 0) {
    GTEST_SKIP() << "prlimit (util-linux) is not installed";
  }
  const auto store = tempDir("full_store");
  const auto out = tempDir("full_out");
  // SIGXFSZ ignored, as a server under systemd would: writes past the limit fail with EFBIG.
  const std::string command = "trap '' XFSZ; exec prlimit --fsize=2097152 " +
                              test::edgeslamBinary().string() + " run --dataset " +
                              test::sharedPath(kSequence).string() +
                              " --mode edge --sensor rgbd --max-frames 300 --vocab none --maps " +
                              store.string() + " --map full --out " + out.string() + " 2>&1";
  std::string output;
  FILE* pipe = popen(command.c_str(), "r");
  ASSERT_NE(pipe, nullptr);
  char buffer[4096];
  while (const std::size_t n = fread(buffer, 1, sizeof(buffer), pipe)) output.append(buffer, n);
  const int status = pclose(pipe);
  ASSERT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << output;

  std::ifstream metrics_file(out / "metrics.json");
  const auto metrics = nlohmann::json::parse(metrics_file, nullptr, false);
  ASSERT_TRUE(metrics.is_object()) << output;
  EXPECT_GE(metrics["tracked"].get<double>(), 0.95 * metrics["frames"].get<double>());
  const auto& stored = metrics["store"];
  EXPECT_GE(stored["failures"].get<int>(), 1) << stored.dump();
  EXPECT_LT(stored["keyframes"].get<int>(), metrics["keyframes"].get<int>()) << stored.dump();
  bool warned = false;
  for (const auto& warning : metrics["warnings"]) {
    warned |= warning.get<std::string>().find("map store:") != std::string::npos;
  }
  EXPECT_TRUE(warned) << metrics["warnings"].dump();
  EXPECT_NE(output.find("map store: "), std::string::npos) << output;

  // Without the limit the store opens, whole, with the keyframes written before it filled up
  // (how many depends on how fast the run fills the first batches).
  const auto info = test::runEdgeslam("map info full --json --maps " + store.string(), false);
  ASSERT_EQ(info.exit_code, 0) << info.output;
  const auto summary = jsonOf(info);
  EXPECT_EQ(summary["keyframes"], stored["keyframes"]);
  std::filesystem::remove_all(store);
  std::filesystem::remove_all(out);
}

}  // namespace
}  // namespace edgeslam
