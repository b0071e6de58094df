#include "linkem/link_trace.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>

namespace edgeslam {
namespace {

LinkTrace parseText(const std::string& text) {
  std::istringstream in(text);
  return LinkTrace::parse(in, "test.trace");
}

std::string parseError(const std::string& text) {
  try {
    parseText(text);
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "no error";
}

TEST(LinkTrace, ParsesPointsCommentsAndOptionalColumns) {
  const LinkTrace trace = parseText(
      "# time up down delay_up delay_down [jitter [loss]]\n"
      "0   10 20 5 6\n"
      "\n"
      "1.5 1  2  50 60 7   # congested\n"
      "2.0 30 40 1 1 0 0.01\n");
  ASSERT_EQ(trace.points().size(), 3u);
  EXPECT_DOUBLE_EQ(trace.points()[1].delay_down_ms, 60.0);
  EXPECT_FALSE(trace.points()[0].jitter_ms.has_value());
  EXPECT_DOUBLE_EQ(*trace.points()[1].jitter_ms, 7.0);
  EXPECT_DOUBLE_EQ(*trace.points()[2].loss, 0.01);
  // The last point lasts as long as the step before it (0.5 s).
  EXPECT_DOUBLE_EQ(trace.periodS(), 2.5);
}

TEST(LinkTrace, ReplaysStepsAndLoops) {
  const LinkTrace trace = parseText("0 10 20 5 6\n1 1 2 50 60 7\n2 30 40 1 1\n");
  LinkSettings base;
  base.jitter_ms = 3.0;
  base.loss = 0.02;
  EXPECT_DOUBLE_EQ(trace.settingsAt(0.5, base).up_mbps, 10.0);
  EXPECT_DOUBLE_EQ(trace.settingsAt(0.5, base).jitter_ms, 3.0);  // from the base
  EXPECT_DOUBLE_EQ(trace.settingsAt(1.0, base).up_mbps, 1.0);
  EXPECT_DOUBLE_EQ(trace.settingsAt(1.2, base).jitter_ms, 7.0);
  EXPECT_DOUBLE_EQ(trace.settingsAt(1.2, base).loss, 0.02);
  EXPECT_DOUBLE_EQ(trace.settingsAt(2.9, base).up_mbps, 30.0);
  EXPECT_DOUBLE_EQ(trace.settingsAt(3.1, base).up_mbps, 10.0);  // period 3 s
  EXPECT_DOUBLE_EQ(trace.settingsAt(4.5, base).delay_up_ms, 50.0);
}

TEST(LinkTrace, MalformedLinesNameFileAndLine) {
  EXPECT_NE(parseError("0 1 2 3 4\nfoo 1 2 3 4\n").find("test.trace:2:"), std::string::npos);
  EXPECT_NE(parseError("0 1 2 3\n").find("test.trace:1: expected 5 to 7 columns"),
            std::string::npos);
  EXPECT_NE(parseError("0 1 2 3 4\n1 1 -2 3 4\n").find("test.trace:2: link setting down_mbps"),
            std::string::npos);
  EXPECT_NE(parseError("0 1 2 3 4\n2 1 2 3 4\n1 1 2 3 4\n").find("test.trace:3: time 1 does not"),
            std::string::npos);
  EXPECT_NE(parseError("# only\n0.5 1 2 3 4\n").find("test.trace:2: the first point"),
            std::string::npos);
  EXPECT_NE(parseError("0 1 2 3 4 0 1.5\n").find("loss"), std::string::npos);
  EXPECT_NE(parseError("0 1 2 3 4x\n").find("delay_down_ms '4x'"), std::string::npos);
  EXPECT_NE(parseError("# nothing\n").find("no points"), std::string::npos);
}

TEST(LinkTrace, LoadsFilesAndNamesMissingOnes) {
  const auto path = std::filesystem::temp_directory_path() / "edgeslam_link_trace_test.trace";
  {
    std::ofstream out(path);
    out << "0 5 5 1 1\n0.25 bad\n";
  }
  try {
    LinkTrace::load(path);
    FAIL() << "no exception";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(path.string() + ":2:"), std::string::npos) << e.what();
  }
  {
    std::ofstream out(path);
    out << "0 5 5 1 1\n";
  }
  EXPECT_DOUBLE_EQ(LinkTrace::load(path).periodS(), 1.0);
  std::filesystem::remove(path);
  EXPECT_THROW(LinkTrace::load(path), std::runtime_error);
}

}  // namespace
}  // namespace edgeslam
