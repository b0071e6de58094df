// Runs `edgeslam eval ...` and checks its JSON output and its failures.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "support/edgeslam_command.h"
#include "support/shared_data.h"

namespace edgeslam {
namespace {

using test::CommandResult;

// stdout only, so that --json output parses on its own; calls that want stderr add 2>&1.
CommandResult runEdgeslam(const std::string& arguments) {
  return test::runEdgeslam(arguments, /*merge_stderr=*/false);
}

std::string evo(const std::string& name) {
  return test::sharedPath("datasets/trajectories/evo/" + name).string();
}

TEST(EvalCli, AteJsonOnFr2Desk) {
  EDGESLAM_REQUIRE_SHARED("datasets/trajectories/evo/fr2_desk_ORB.txt");
  const auto plot = std::filesystem::temp_directory_path() / "edgeslam_eval_cli_ate.svg";
  std::filesystem::remove(plot);
  const CommandResult r =
      runEdgeslam("eval ate --gt " + evo("fr2_desk_groundtruth.txt") + " --est " +
                  evo("fr2_desk_ORB.txt") + " --json --plot " + plot.string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const auto j = nlohmann::json::parse(r.output);  // exactly one object, nothing else
  EXPECT_EQ(j.at("metric"), "ate");
  EXPECT_EQ(j.at("align"), "se3");
  EXPECT_EQ(j.at("pairs"), 2223);
  EXPECT_NEAR(j.at("rmse_m").get<double>(), 0.008144, 5e-6);
  EXPECT_NEAR(j.at("median_m").get<double>(), 0.007432, 5e-6);
  EXPECT_DOUBLE_EQ(j.at("scale").get<double>(), 1.0);
  ASSERT_TRUE(std::filesystem::exists(plot));
  EXPECT_GT(std::filesystem::file_size(plot), 10000U);
  std::filesystem::remove(plot);
}

TEST(EvalCli, KittiAndRpeJson) {
  EDGESLAM_REQUIRE_SHARED("datasets/trajectories/evo/KITTI_00_ORB.txt");
  const std::string files =
      " --gt " + evo("KITTI_00_gt.txt") + " --est " + evo("KITTI_00_ORB.txt") + " --json";
  const CommandResult kitti = runEdgeslam("eval kitti" + files);
  ASSERT_EQ(kitti.exit_code, 0) << kitti.output;
  const auto k = nlohmann::json::parse(kitti.output);
  EXPECT_NEAR(k.at("t_rel_percent").get<double>(), 0.699729, 1e-4);
  EXPECT_NEAR(k.at("r_rel_deg_per_100m").get<double>(), 0.253330, 1e-4);
  EXPECT_EQ(k.at("lengths").size(), 8U);
  EXPECT_EQ(k.at("lengths")[0].at("length_m"), 100.0);

  const CommandResult rpe =
      runEdgeslam("eval rpe" + files + " --delta 100 --delta-unit metres --format kitti");
  ASSERT_EQ(rpe.exit_code, 0) << rpe.output;
  const auto r = nlohmann::json::parse(rpe.output);
  EXPECT_EQ(r.at("metric"), "rpe");
  EXPECT_EQ(r.at("delta_unit"), "metres");
  EXPECT_GT(r.at("pairs").get<int>(), 4000);
  EXPECT_GT(r.at("trans_rmse_m").get<double>(), 0.1);
  EXPECT_LT(r.at("trans_rmse_m").get<double>(), 10.0);
  EXPECT_GT(r.at("rot_rmse_deg").get<double>(), 0.0);
}

TEST(EvalCli, TextTableByDefault) {
  EDGESLAM_REQUIRE_SHARED("datasets/trajectories/evo/fr2_desk_ORB.txt");
  const CommandResult r = runEdgeslam("eval ate --gt " + evo("fr2_desk_groundtruth.txt") +
                                      " --est " + evo("fr2_desk_ORB.txt") + " --align sim3");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("sim3 alignment, 2223 pose pairs"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("rmse"), std::string::npos) << r.output;
}

TEST(EvalCli, FailuresExitNonZeroWithMessage) {
  const CommandResult missing =
      runEdgeslam("eval ate --gt /nonexistent/gt.txt --est /nonexistent/est.txt 2>&1");
  EXPECT_NE(missing.exit_code, 0);
  EXPECT_NE(missing.output.find("/nonexistent/gt.txt"), std::string::npos) << missing.output;

  const auto dir = std::filesystem::temp_directory_path();
  const auto gt = dir / "edgeslam_eval_cli_gt.txt";
  const auto est = dir / "edgeslam_eval_cli_est.txt";
  std::ofstream(gt) << "1.0 0 0 0 0 0 0 1\n2.0 1 0 0 0 0 0 1\n";
  std::ofstream(est) << "50.0 0 0 0 0 0 0 1\n";
  const CommandResult apart =
      runEdgeslam("eval ate --gt " + gt.string() + " --est " + est.string() + " 2>&1");
  EXPECT_NE(apart.exit_code, 0);
  EXPECT_NE(apart.output.find("no poses associated"), std::string::npos) << apart.output;

  std::ofstream(est) << "1.0 0 0 0 0 0 0 1\n2.0 1 0 0 0 0 0 1\n";
  const CommandResult few =
      runEdgeslam("eval ate --gt " + gt.string() + " --est " + est.string() + " 2>&1");
  EXPECT_NE(few.exit_code, 0);
  EXPECT_NE(few.output.find("at least 3 pose pairs"), std::string::npos) << few.output;
  std::filesystem::remove(gt);
  std::filesystem::remove(est);
}

}  // namespace
}  // namespace edgeslam
