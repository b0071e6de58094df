// `edgeslam report OUT_DIR` on a real run's output: one self-contained page with the charts' data.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

#include "support/edgeslam_command.h"
#include "support/shared_data.h"

namespace edgeslam {
namespace {

namespace fs = std::filesystem;

std::string readAll(const fs::path& path) {
  std::ifstream in(path);
  std::ostringstream out;
  out << in.rdbuf();
  return out.str();
}

TEST(ReportCommand, WritesOneSelfContainedPageForARun) {
  EDGESLAM_REQUIRE_SHARED("datasets/7scenes-redkitchen-1000");
  const fs::path out = fs::path(::testing::TempDir()) / "edgeslam_report_test";
  fs::remove_all(out);
  const auto run = test::runEdgeslam(
      "run --dataset " + test::sharedPath("datasets/7scenes-redkitchen-1000").string() +
      " --mode local --max-frames 60 --vocab none --out " + out.string());
  ASSERT_EQ(run.exit_code, 0) << run.output;
  ASSERT_TRUE(fs::exists(out / "groundtruth.tum"));
  const auto report = test::runEdgeslam("report " + out.string());
  ASSERT_EQ(report.exit_code, 0) << report.output;
  const std::string html = readAll(out / "report.html");
  // Nothing is fetched: no external script, style, image or link target.
  for (const char* external : {"src=\"http", "href=\"http", "src='http", "@import", "<link"}) {
    EXPECT_EQ(html.find(external), std::string::npos) << external;
  }
  EXPECT_NE(html.find("uPlot"), std::string::npos);  // the library, inlined
  const std::string marker = "window.EDGESLAM_REPORT = ";
  const auto start = html.find(marker);
  ASSERT_NE(start, std::string::npos);
  const auto end = html.find(";</script>", start);
  const auto data =
      nlohmann::json::parse(html.substr(start + marker.size(), end - start - marker.size()));
  // Trajectory against ground truth, the error over time, per-frame latency and bytes.
  ASSERT_TRUE(data.contains("top_view"));
  EXPECT_EQ(data["top_view"]["truth_x"].size(), data["top_view"]["estimate_x"].size());
  EXPECT_GT(data["top_view"]["truth_x"].size(), 50u);
  EXPECT_EQ(data["error"]["t"].size(), data["error"]["error_m"].size());
  EXPECT_LT(data["error"]["rmse_m"].get<double>(), 0.2);
  EXPECT_EQ(data["frames"]["client_ms"].size(), 60u);
  EXPECT_EQ(data["frames"]["e2e_ms"].size(), 60u);
  EXPECT_GT(data["frames"]["client_ms"][10].get<double>(), 0.0);
  EXPECT_EQ(data["frames"]["uplink_bytes"].size(), 60u);
  fs::remove_all(out);
}

TEST(ReportCommand, AFolderWithoutARunIsAClearError) {
  const auto report = test::runEdgeslam("report /nonexistent/run");
  EXPECT_EQ(report.exit_code, 1);
  EXPECT_NE(report.output.find("/nonexistent/run"), std::string::npos) << report.output;
}

}  // namespace
}  // namespace edgeslam
