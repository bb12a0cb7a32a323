// The HTTP request path without sockets (runtime/web/http/request_limits):
// each bound and framing rule gives its clear 4xx before a handler runs.
#include <gtest/gtest.h>

#include <unistd.h>

#include <cstdlib>
#include <string>

#include "runtime/web/descriptor_budget.hpp"
#include "runtime/web/http/request_limits.hpp"
#include "runtime/web/http/router.hpp"
#include "runtime/web/static_files.hpp"

namespace syncplc::web::http {
namespace {

Refusal parse(const std::string& bytes, Request* out = nullptr, const Limits& limits = {}) {
  Request r;
  return parse_request(bytes, limits, out ? out : &r);
}

TEST(HttpRequest, ReadsPathQueryHeadersAndBody) {
  Request r;
  std::size_t used = 0;
  const std::string one = "POST /api/v1/tags/a%20b?refs=x%2Cy&rate=5+1 HTTP/1.1\r\nHost: h\r\n"
                          "Content-Type: application/json\r\nContent-Length: 2\r\n\r\n{}";
  const Refusal why = parse_request(one + "GET / HTTP/1.1\r\nHost: h\r\n\r\n", Limits{}, &r, &used);
  ASSERT_FALSE(why) << why.message;
  EXPECT_EQ(r.method, "POST");
  EXPECT_EQ(r.path, "/api/v1/tags/a b");
  EXPECT_EQ(r.get_param_value("refs"), "x,y");
  EXPECT_EQ(r.get_param_value("rate"), "5 1");
  EXPECT_FALSE(r.has_param("nope"));
  EXPECT_EQ(r.get_header_value("content-type"), "application/json");
  EXPECT_EQ(r.body, "{}");
  EXPECT_EQ(used, one.size());  // the pipelined second request is left for the next read
}

TEST(HttpRequest, ChunkedBodyIsTaken) {
  Request r;
  const Refusal why = parse("POST /x HTTP/1.1\r\nHost: h\r\nTransfer-Encoding: chunked\r\n\r\n2\r\n{}\r\n0\r\n\r\n", &r);
  ASSERT_FALSE(why) << why.message;
  EXPECT_EQ(r.body, "{}");
}

TEST(HttpRequest, TrailerFieldsAreRefused) {
  // After the head's checks: a trailer must not add a Host or an Authorization.
  EXPECT_EQ(parse("POST /x HTTP/1.1\r\nHost: h\r\nTransfer-Encoding: chunked\r\n\r\n2\r\n{}\r\n0\r\n"
                  "Authorization: Bearer x\r\n\r\n").status,
            400);
}

TEST(HttpRequest, OneValidContentLengthOrA400) {
  EXPECT_EQ(parse("POST /x HTTP/1.1\r\nHost: h\r\nContent-Length: 2\r\nContent-Length: 2\r\n\r\n{}").status, 400);
  EXPECT_EQ(parse("POST /x HTTP/1.1\r\nHost: h\r\nContent-Length: 2\r\nContent-Length: 7\r\n\r\n{}").status, 400);
  EXPECT_EQ(parse("POST /x HTTP/1.1\r\nHost: h\r\nContent-Length: abc\r\n\r\n{}").status, 400);
  EXPECT_EQ(parse("POST /x HTTP/1.1\r\nHost: h\r\nContent-Length: 2, 2\r\n\r\n{}").status, 400);
  EXPECT_EQ(parse("POST /x HTTP/1.1\r\nHost: h\r\nContent-Length: -1\r\n\r\n{}").status, 400);
  EXPECT_EQ(parse("POST /x HTTP/1.1\r\nHost: h\r\nContent-Length: 2\r\nTransfer-Encoding: chunked\r\n\r\n{}").status, 400);
  EXPECT_EQ(parse("POST /x HTTP/1.1\r\nHost: h\r\nTransfer-Encoding: chunked\r\nContent-Length: 2\r\n\r\n{}").status, 400);
  EXPECT_EQ(parse("POST /x HTTP/1.1\r\nHost: h\r\nTransfer-Encoding: gzip, chunked\r\n\r\n").status, 400);
  EXPECT_EQ(parse("POST /x HTTP/1.1\r\nHost: h\r\nTransfer-Encoding: identity\r\n\r\n").status, 400);
}

TEST(HttpRequest, CompressedBodiesAreRefusedUnread) {
  const Refusal r = parse("POST /x HTTP/1.1\r\nHost: h\r\nContent-Encoding: gzip\r\nContent-Length: 510000\r\n\r\n");
  EXPECT_EQ(r.status, 415) << r.message;
  EXPECT_FALSE(parse("POST /x HTTP/1.1\r\nHost: h\r\nContent-Encoding: identity\r\nContent-Length: 0\r\n\r\n"));
}

TEST(HttpRequest, BodiesPastTheLimitAre413BeforeTheyAreRead) {
  Limits l;
  l.max_body = 100;
  l.max_upload_body = 1000;
  // The head alone: the length says it all.
  EXPECT_EQ(parse("POST /api/v1/login HTTP/1.1\r\nHost: h\r\nContent-Length: 101\r\n\r\n", nullptr, l).status, 413);
  EXPECT_EQ(parse("POST /api/v1/projects/load HTTP/1.1\r\nHost: h\r\nContent-Length: 1001\r\n\r\n", nullptr, l).status, 413);
  // Within an upload's limit: read (incomplete here, no refusal).
  EXPECT_EQ(parse("POST /api/v1/projects/load HTTP/1.1\r\nHost: h\r\nContent-Length: 999\r\n\r\n", nullptr, l).status, 0);
  // Chunked: refused at the chunk that passes the limit, the rest never read.
  std::string chunked = "POST /api/v1/login HTTP/1.1\r\nHost: h\r\nTransfer-Encoding: chunked\r\n\r\n";
  for (int i = 0; i < 3; ++i) chunked += "3c\r\n" + std::string(60, 'x') + "\r\n";
  EXPECT_EQ(parse(chunked, nullptr, l).status, 413);
}

TEST(HttpRequest, LongLinesAndHeaderBlocksAreRefused) {
  const Limits l;
  EXPECT_EQ(parse("GET /" + std::string(l.max_header_bytes + 10, 'a'), nullptr, l).status, 414);
  EXPECT_EQ(parse("GET /" + std::string(l.max_target, 'a') + " HTTP/1.1\r\nHost: h\r\n\r\n", nullptr, l).status, 414);
  std::string many = "GET / HTTP/1.1\r\nHost: h\r\n";
  for (std::size_t i = 0; i < l.max_header_fields; ++i) many += "X-" + std::to_string(i) + ": 1\r\n";
  EXPECT_EQ(parse(many + "\r\n", nullptr, l).status, 431);
  std::string big = "GET / HTTP/1.1\r\nHost: h\r\n";
  while (big.size() < l.max_header_bytes + 100) big += "X-Long: " + std::string(1000, 'b') + "\r\n";
  EXPECT_EQ(parse(big, nullptr, l).status, 431);
}

TEST(HttpRequest, MalformedRequestsAre400) {
  EXPECT_EQ(parse("GARBAGE\r\n\r\n").status, 400);
  EXPECT_EQ(parse("GET / HTTP/1.1\r\n\r\n").status, 400);  // no Host
  EXPECT_EQ(parse("GET / HTTP/1.1\r\nHost: a\r\nHost: b\r\n\r\n").status, 400);
  EXPECT_EQ(parse("GET /%zz HTTP/1.1\r\nHost: h\r\n\r\n").status, 400);
  EXPECT_EQ(parse("GET /a%00b HTTP/1.1\r\nHost: h\r\n\r\n").status, 400);
  EXPECT_EQ(parse("GET http://h/ HTTP/1.1\r\nHost: h\r\n\r\n").status, 400);
  EXPECT_EQ(parse("TRACE / HTTP/1.1\r\nHost: h\r\n\r\n").status, 405);
  EXPECT_EQ(parse("PATCH /api/v1/subscriptions/x HTTP/1.1\r\nHost: h\r\n\r\n{}").status, 411);  // PATCH carries a body
  EXPECT_EQ(parse("POST /api/v1/login HTTP/1.1\r\nHost: h\r\n\r\n{}").status, 411);  // a body without a length
  EXPECT_EQ(parse("GET / HTTP/2.0\r\nHost: h\r\n\r\n").status, 400);  // Beast takes HTTP/1.0 and 1.1 only
  EXPECT_EQ(parse("GET / HTTP/1.2\r\nHost: h\r\n\r\n").status, 400);
}

TEST(HttpRouter, MatchesMethodPathAndGroups) {
  Router router;
  std::string got;
  router.Get(R"(/api/v1/tags/([^/]+))", [&](const Request& req, Response& res) {
    got = req.matches[1];
    res.set_content("ok", "text/plain");
  });
  Request req;
  Response res;
  req.method = "GET";
  req.path = "/api/v1/tags/speed";
  EXPECT_EQ(router.dispatch(req, res), Router::Outcome::Handled);
  EXPECT_EQ(got, "speed");
  req.method = "HEAD";  // as GET
  EXPECT_EQ(router.dispatch(req, res), Router::Outcome::Handled);
  req.method = "PUT";
  EXPECT_EQ(router.dispatch(req, res), Router::Outcome::NoRoute);
  req.method = "GET";
  req.path = "/api/v1/tags/a/b";
  EXPECT_EQ(router.dispatch(req, res), Router::Outcome::NoRoute);
}

TEST(HttpDescriptors, TheHttpServerKeepsToItsShare) {
  EXPECT_EQ(http_connection_budget(256, 20000), 256u);
  EXPECT_EQ(http_connection_budget(2000, 1024), (1024 - kDescriptorsReserved) / 2);
  EXPECT_EQ(http_connection_budget(256, 100), 1u);
}

TEST(HttpStaticFiles, ServesTheRootOnlyWithTheirTypes) {
  const std::string base = ::testing::TempDir() + "syncplc_static_files_" + std::to_string(getpid());
  const std::string root = base + "/dist";
  ASSERT_EQ(std::system(("rm -rf " + base + " && mkdir -p " + root + "/assets && echo hi > " + root +
                         "/index.html && echo x > " + root + "/assets/a.mjs && echo secret > " + root +
                         "/../outside.txt && ln -s ../outside.txt " + root + "/link.txt").c_str()),
            0);
  StaticFiles files;
  ASSERT_TRUE(files.open(root));
  Response res;
  ASSERT_TRUE(files.serve("/", res));
  EXPECT_EQ(res.body, "hi\n");
  EXPECT_EQ(res.get_header_value("Content-Type"), "text/html");
  ASSERT_TRUE(files.serve("/assets/a.mjs", res));
  EXPECT_EQ(res.get_header_value("Content-Type"), "text/javascript");
  EXPECT_FALSE(files.serve("/../outside.txt", res));
  EXPECT_FALSE(files.serve("/assets/../../outside.txt", res));
  EXPECT_FALSE(files.serve("/link.txt", res));  // a link out of the root
  EXPECT_FALSE(files.serve("/nope.js", res));
  std::system(("rm -rf " + base).c_str());
}

}  // namespace
}  // namespace syncplc::web::http
