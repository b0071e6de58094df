// The binary restarts itself once with glibc's heap on transparent huge pages (same pid), unless
// told not to (apps/edgeslam/huge_page_heap.h): seen in a running server's environment.
#include <gtest/gtest.h>

#include <chrono>
#include <cstdlib>
#include <fstream>
#include <iterator>
#include <string>

#include "io/temp_folder.h"
#include "support/child_process.h"
#include "support/edgeslam_command.h"
#include "util/transparent_huge_pages.h"

namespace edgeslam {
namespace {

// The environment of a server started with `huge_pages` ("" = the variable unset), once it
// listens.
std::string serverEnvironment(const std::string& huge_pages) {
  test::TempFolder folder;
  if (huge_pages.empty()) {
    unsetenv("EDGESLAM_HUGE_PAGES");
  } else {
    setenv("EDGESLAM_HUGE_PAGES", huge_pages.c_str(), 1);
  }
  const char* tunables = std::getenv("GLIBC_TUNABLES");
  EXPECT_EQ(tunables, nullptr) << "the test's own environment sets GLIBC_TUNABLES";
  test::ChildProcess server(test::edgeslamBinary(),
                            {"server", "--listen", "127.0.0.1:0", "--semantic", "off", "--vocab",
                             "none", "--maps", (folder / "maps").string()},
                            folder / "server.log");
  unsetenv("EDGESLAM_HUGE_PAGES");
  EXPECT_TRUE(server.waitForLog("listening on", std::chrono::seconds(30)));
  std::ifstream in("/proc/" + std::to_string(server.pid()) + "/environ", std::ios::binary);
  std::string environment((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  server.signal(SIGINT);
  server.wait(std::chrono::seconds(15));
  return environment;
}

TEST(HugePageHeap, TheBinaryRunsWithTheTunableUnlessToldNot) {
  if (!kernelOffersTransparentHugePages())
    GTEST_SKIP() << "transparent huge pages are off on this host";
  EXPECT_NE(serverEnvironment("").find("GLIBC_TUNABLES=glibc.malloc.hugetlb=1"), std::string::npos);
  EXPECT_EQ(serverEnvironment("0").find("GLIBC_TUNABLES"), std::string::npos);
}

}  // namespace
}  // namespace edgeslam
