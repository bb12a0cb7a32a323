// --http's address, the settings' checks and who may read without a login
// (docs/http-api.md).
#include <gtest/gtest.h>

#include "runtime/web/web_config.hpp"

namespace syncplc::web {
namespace {

TEST(WebConfig, AddressPortAndOff) {
  WebConfig c;
  std::string why;
  ASSERT_TRUE(parse_http_address("9090", c, &why)) << why;
  EXPECT_EQ(c.bind, "127.0.0.1");
  EXPECT_EQ(c.port, 9090);
  EXPECT_TRUE(c.explicit_address);
  ASSERT_TRUE(parse_http_address("0.0.0.0:8443", c, &why)) << why;
  EXPECT_EQ(c.bind, "0.0.0.0");
  EXPECT_EQ(c.port, 8443);
  ASSERT_TRUE(parse_http_address("[::1]:8080", c, &why)) << why;
  EXPECT_EQ(c.bind, "::1");
  ASSERT_TRUE(parse_http_address("off", c, &why));
  EXPECT_FALSE(c.enabled);
}

TEST(WebConfig, BadAddressesSayWhy) {
  WebConfig c;
  std::string why;
  EXPECT_FALSE(parse_http_address("127.0.0.1:99999", c, &why));
  EXPECT_NE(why.find("0..65535"), std::string::npos) << why;
  EXPECT_FALSE(parse_http_address("plc.example:80", c, &why));
  EXPECT_NE(why.find("not an IP address"), std::string::npos) << why;
  EXPECT_FALSE(parse_http_address("[::1]8080", c, &why));
  EXPECT_FALSE(parse_http_address("12x", c, &why));
}

TEST(WebConfig, PlainHttpBeyondThisMachineNeedsConsent) {
  WebConfig c;
  std::string why;
  c.bind = "0.0.0.0";
  EXPECT_FALSE(check_config(c, &why));
  EXPECT_NE(why.find("HTTPS"), std::string::npos) << why;
  c.allow_plain_remote = true;
  EXPECT_TRUE(check_config(c, &why)) << why;
  c.bind = "127.0.0.5";
  c.allow_plain_remote = false;
  EXPECT_TRUE(check_config(c, &why)) << why;
}

TEST(WebConfig, TlsNeedsBothReadableFiles) {
  WebConfig c;
  std::string why;
  c.tls_cert = "/etc/hostname";
  EXPECT_FALSE(check_config(c, &why));
  EXPECT_NE(why.find("both"), std::string::npos) << why;
  c.tls_key = "/nonexistent/key.pem";
  EXPECT_FALSE(check_config(c, &why));
  EXPECT_NE(why.find("/nonexistent/key.pem"), std::string::npos) << why;
}

TEST(WebConfig, AnonymousReadsOnlyOnLoopbackUnlessSaid) {
  WebConfig c;
  EXPECT_TRUE(anonymous_reads(c));
  c.bind = "192.0.2.1";
  EXPECT_FALSE(anonymous_reads(c));
  c.anonymous_read = true;
  EXPECT_TRUE(anonymous_reads(c));
  c.bind = "127.0.0.1";
  c.anonymous_read = false;
  EXPECT_FALSE(anonymous_reads(c));
  EXPECT_TRUE(is_loopback("127.1.2.3"));
  EXPECT_TRUE(is_loopback("::1"));
  EXPECT_FALSE(is_loopback("10.0.0.1"));
}

}  // namespace
}  // namespace syncplc::web
