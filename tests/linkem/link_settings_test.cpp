#include "linkem/link_settings.h"

#include <gtest/gtest.h>

#include <stdexcept>
#include <string>

#include "linkem/socket.h"

namespace edgeslam {
namespace {

TEST(LinkSettings, ProfilesAreValidAndOrderedByQuality) {
  for (const std::string& name : linkProfileNames()) {
    EXPECT_NO_THROW(validate(linkProfile(name))) << name;
  }
  const LinkSettings wifi5 = linkProfile("wifi5");
  const LinkSettings wifi24 = linkProfile("wifi24");
  const LinkSettings lte = linkProfile("lte");
  const LinkSettings congested = linkProfile("lte-congested");
  EXPECT_LT(wifi5.baseRttMs(), wifi24.baseRttMs());
  EXPECT_LT(wifi24.baseRttMs(), lte.baseRttMs());
  EXPECT_LT(lte.baseRttMs(), congested.baseRttMs());
  EXPECT_GT(wifi5.up_mbps, wifi24.up_mbps);
  EXPECT_GT(wifi24.up_mbps, lte.up_mbps);
  EXPECT_GT(lte.up_mbps, congested.up_mbps);
}

TEST(LinkSettings, UnknownProfileListsTheKnownOnes) {
  try {
    linkProfile("wifi6");
    FAIL() << "no exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("wifi6"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("lte-congested"), std::string::npos);
  }
}

TEST(LinkSettings, InvalidValuesNameTheField) {
  LinkSettings s;
  s.jitter_ms = -1.0;
  try {
    validate(s);
    FAIL() << "no exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("jitter_ms"), std::string::npos);
  }
  s = LinkSettings{};
  s.loss = 1.0;
  EXPECT_THROW(validate(s), std::invalid_argument);
}

TEST(HostPortParsing, AcceptsNamesAddressesAndBracketedIpv6) {
  EXPECT_EQ(parseHostPort("127.0.0.1:5000").port, 5000);
  EXPECT_EQ(parseHostPort("localhost:0").host, "localhost");
  EXPECT_EQ(parseHostPort("[::1]:80").host, "::1");
  EXPECT_THROW(parseHostPort("localhost"), std::runtime_error);
  EXPECT_THROW(parseHostPort("localhost:99999"), std::runtime_error);
  EXPECT_THROW(parseHostPort("localhost:http"), std::runtime_error);
  EXPECT_THROW(parseHostPort(":80"), std::runtime_error);
}

}  // namespace
}  // namespace edgeslam
