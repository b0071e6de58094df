#include "eval/trajectory_input.h"

#include <gtest/gtest.h>

#include <fstream>
#include <string>

#include "eval/eval_error.h"

namespace edgeslam {
namespace {

class TrajectoryInputTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() /
           ("edgeslam_eval_input_" +
            std::to_string(::testing::UnitTest::GetInstance()->random_seed()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }

  std::filesystem::path write(const std::string& name, const std::string& text) {
    const auto path = dir_ / name;
    std::ofstream(path) << text;
    return path;
  }

  std::filesystem::path dir_;
};

const char* kTum =
    "# timestamp tx ty tz qx qy qz qw\n"
    "10.0 0 0 0 0 0 0 1\n"
    "10.1 1 0 0 0 0 0 1\n"
    "10.2 2 0 0 0 0 0 1\n";
const char* kKitti =
    "1 0 0 0 0 1 0 0 0 0 1 0\n"
    "1 0 0 1 0 1 0 0 0 0 1 0\n"
    "1 0 0 2 0 1 0 0 0 0 1 0\n";

TEST_F(TrajectoryInputTest, GuessesFormatFromValuesPerLine) {
  EXPECT_EQ(guessTrajectoryFormat(write("a.txt", kTum)), TrajectoryFormat::kTum);
  EXPECT_EQ(guessTrajectoryFormat(write("b.txt", kKitti)), TrajectoryFormat::kKitti);
  try {
    guessTrajectoryFormat(write("c.txt", "1 2 3 4\n"));
    FAIL() << "no exception";
  } catch (const EvalError& e) {
    EXPECT_NE(std::string(e.what()).find("4 values"), std::string::npos) << e.what();
  }
}

TEST_F(TrajectoryInputTest, MissingFileIsNamed) {
  try {
    loadTrajectory(dir_ / "absent.txt", TrajectoryFormat::kAuto);
    FAIL() << "no exception";
  } catch (const EvalError& e) {
    EXPECT_NE(std::string(e.what()).find("absent.txt"), std::string::npos) << e.what();
  }
}

TEST_F(TrajectoryInputTest, KittiFilesPairByIndexAndTumByTime) {
  const auto kitti = loadTrajectory(write("k.txt", kKitti), TrajectoryFormat::kAuto);
  EXPECT_FALSE(kitti.has_timestamps);
  EXPECT_EQ(pairTrajectories(kitti, kitti).size(), 3U);

  const auto tum = loadTrajectory(write("t.txt", kTum), TrajectoryFormat::kAuto);
  const auto shifted = loadTrajectory(
      write("s.txt", "10.105 5 0 0 0 0 0 1\n10.205 6 0 0 0 0 0 1\n"), TrajectoryFormat::kTum);
  const PosePairs pairs = pairTrajectories(tum, shifted, 0.02);
  ASSERT_EQ(pairs.size(), 2U);
  EXPECT_DOUBLE_EQ(pairs[0].gt.translation().x(), 1.0);
  EXPECT_DOUBLE_EQ(pairs[0].est.translation().x(), 5.0);
}

TEST_F(TrajectoryInputTest, KittiWithTimesPairsWithTum) {
  const auto kitti = loadTrajectory(write("k.txt", kKitti), TrajectoryFormat::kKitti,
                                    std::vector<double>{10.0, 10.1, 10.2});
  const auto tum = loadTrajectory(write("t.txt", kTum), TrajectoryFormat::kTum);
  EXPECT_EQ(pairTrajectories(kitti, tum).size(), 3U);
  EXPECT_THROW(loadTrajectory(write("k2.txt", kKitti), TrajectoryFormat::kKitti,
                              std::vector<double>{1.0, 2.0}),
               EvalError);
  const auto unstamped = loadTrajectory(write("k3.txt", kKitti), TrajectoryFormat::kKitti);
  EXPECT_THROW(pairTrajectories(unstamped, tum), EvalError);
}

TEST_F(TrajectoryInputTest, NoAssociationReportsTimeRanges) {
  const auto gt = loadTrajectory(write("t.txt", kTum), TrajectoryFormat::kTum);
  const auto est =
      loadTrajectory(write("late.txt", "99.5 0 0 0 0 0 0 1\n"), TrajectoryFormat::kTum);
  try {
    pairTrajectories(gt, est, 0.02);
    FAIL() << "no exception";
  } catch (const EvalError& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("10.000000 .. 10.200000"), std::string::npos) << message;
    EXPECT_NE(message.find("99.500000"), std::string::npos) << message;
  }
}

TEST_F(TrajectoryInputTest, EmptyFileIsAnError) {
  EXPECT_THROW(loadTrajectory(write("e.txt", "# nothing\n"), TrajectoryFormat::kAuto), EvalError);
  EXPECT_THROW(loadTrajectory(write("e2.txt", "# nothing\n"), TrajectoryFormat::kTum), EvalError);
}

}  // namespace
}  // namespace edgeslam
