// A worker whose body throws ends alone: the owner hears the cause once, on the worker's thread,
// and failure() keeps it; a body that returns leaves no failure.
#include "util/worker_thread.h"

#include <gtest/gtest.h>

#include <atomic>
#include <stdexcept>
#include <string>
#include <thread>

namespace edgeslam {
namespace {

TEST(WorkerThread, ExceptionIsCaughtNamedAndReportedOnce) {
  WorkerThread worker;
  std::atomic<int> reports{0};
  std::string reported;
  std::thread::id reported_on;
  std::thread::id body_on;
  worker.start(
      "local mapping",
      [&] {
        body_on = std::this_thread::get_id();
        throw std::runtime_error("no memory for the local BA");
      },
      [&](const std::string& cause) {
        ++reports;
        reported = cause;
        reported_on = std::this_thread::get_id();
      });
  worker.join();
  EXPECT_EQ(reports.load(), 1);
  EXPECT_EQ(reported, "local mapping failed: no memory for the local BA");
  EXPECT_EQ(reported_on, body_on);
  ASSERT_TRUE(worker.failure().has_value());
  EXPECT_EQ(*worker.failure(), reported);
}

TEST(WorkerThread, UnknownExceptionsAreCaughtToo) {
  WorkerThread worker;
  worker.start("segmentation", [] { throw 42; });
  worker.join();
  ASSERT_TRUE(worker.failure().has_value());
  EXPECT_EQ(*worker.failure(), "segmentation failed: an unknown exception");
}

TEST(WorkerThread, ABodyThatReturnsLeavesNoFailureAndCanStartAgain) {
  WorkerThread worker;
  int runs = 0;
  worker.start("loop closing", [&] { throw std::logic_error("first"); });
  worker.start("loop closing", [&] { ++runs; });  // joins the first, forgets its failure
  worker.join();
  EXPECT_EQ(runs, 1);
  EXPECT_FALSE(worker.failure().has_value());
  EXPECT_FALSE(worker.joinable());
}

}  // namespace
}  // namespace edgeslam
