// The Server-Sent Events parser of `syncplc watch` (runtime/cli/sse_reader):
// the HTML standard's event-stream rules on bytes cut at any place.
#include <gtest/gtest.h>

#include "runtime/cli/sse_reader.hpp"

namespace {

using syncplc::cli::SseEvent;
using syncplc::cli::SseReader;

// Every event of `text`, fed in pieces of `piece` bytes.
std::vector<SseEvent> read_in_pieces(std::string_view text, std::size_t piece) {
  SseReader r;
  std::vector<SseEvent> out;
  for (std::size_t at = 0; at < text.size(); at += piece)
    for (auto& e : r.feed(text.substr(at, piece))) out.push_back(std::move(e));
  return out;
}

TEST(SseReader, ValuesEventAsTheApiSendsIt) {
  SseReader r;
  auto ev = r.feed("event: values\ndata: {\"t_ns\":1,\"values\":{\"a\":1}}\n\n");
  ASSERT_EQ(ev.size(), 1u);
  EXPECT_EQ(ev[0].type, "values");
  EXPECT_EQ(ev[0].data, "{\"t_ns\":1,\"values\":{\"a\":1}}");
}

TEST(SseReader, ChunksSplitAnywhereGiveTheSameEvents) {
  const std::string text = "event: values\ndata: {\"a\": 1}\n\nevent: error\ndata: {\"error\": \"bye\"}\n\n";
  for (std::size_t piece = 1; piece <= text.size(); ++piece) {
    auto ev = read_in_pieces(text, piece);
    ASSERT_EQ(ev.size(), 2u) << "pieces of " << piece;
    EXPECT_EQ(ev[0].type, "values");
    EXPECT_EQ(ev[0].data, "{\"a\": 1}");
    EXPECT_EQ(ev[1].type, "error");
    EXPECT_EQ(ev[1].data, "{\"error\": \"bye\"}");
  }
}

TEST(SseReader, NothingIsDispatchedBeforeTheEmptyLine) {
  SseReader r;
  EXPECT_TRUE(r.feed("event: values\ndata: 1\n").empty());
  EXPECT_EQ(r.feed("\n").size(), 1u);
}

TEST(SseReader, CrlfAndCrEndLines) {
  for (const char* text : {"event: values\r\ndata: x\r\n\r\n", "event: values\rdata: x\r\r"}) {
    for (std::size_t piece = 1; piece <= 4; ++piece) {
      auto ev = read_in_pieces(text, piece);
      ASSERT_EQ(ev.size(), 1u) << piece;
      EXPECT_EQ(ev[0].type, "values");
      EXPECT_EQ(ev[0].data, "x");
    }
  }
}

TEST(SseReader, CrlfCutBetweenChunksIsOneLineEnd) {
  SseReader r;
  EXPECT_TRUE(r.feed("data: a\r").empty());
  // The LF completes the CR's line end; it is not the empty line that ends the event.
  EXPECT_TRUE(r.feed("\n").empty());
  auto ev = r.feed("\r\n");
  ASSERT_EQ(ev.size(), 1u);
  EXPECT_EQ(ev[0].data, "a");
}

TEST(SseReader, MultiLineDataIsJoinedWithNewlines) {
  SseReader r;
  auto ev = r.feed("data: first\ndata:second\ndata\ndata:  third\n\n");
  ASSERT_EQ(ev.size(), 1u);
  // One space after the colon is dropped, a second is kept; "data" alone is an empty line of data.
  EXPECT_EQ(ev[0].data, "first\nsecond\n\n third");
  EXPECT_EQ(ev[0].type, "message");
}

TEST(SseReader, CommentsAndUnknownFieldsAreSkipped) {
  SseReader r;
  auto ev = r.feed(": keep-alive\n\n:another\nretry: 100\nfoo: bar\nevent: values\n: in between\ndata: 7\n\n");
  ASSERT_EQ(ev.size(), 1u);  // a comment alone and its empty line dispatch nothing
  EXPECT_EQ(ev[0].type, "values");
  EXPECT_EQ(ev[0].data, "7");
}

TEST(SseReader, EventNameLastsForOneEvent) {
  SseReader r;
  auto ev = r.feed("event: error\ndata: a\n\ndata: b\n\nevent:values\ndata: c\n\n");
  ASSERT_EQ(ev.size(), 3u);
  EXPECT_EQ(ev[0].type, "error");
  EXPECT_EQ(ev[1].type, "message");
  EXPECT_EQ(ev[2].type, "values");
}

TEST(SseReader, EventWithoutDataIsNotDispatched) {
  SseReader r;
  EXPECT_TRUE(r.feed("event: values\n\n").empty());
  auto ev = r.feed("data: x\n\n");
  ASSERT_EQ(ev.size(), 1u);
  EXPECT_EQ(ev[0].type, "message");  // the name before the empty line was forgotten
}

TEST(SseReader, IdIsKeptAcrossEvents) {
  SseReader r;
  auto ev = r.feed("id: 7\ndata: a\n\ndata: b\n\n");
  ASSERT_EQ(ev.size(), 2u);
  EXPECT_EQ(ev[0].id, "7");
  EXPECT_EQ(ev[1].id, "7");
}

TEST(SseReader, LeadingByteOrderMarkIsIgnored) {
  auto ev = read_in_pieces("\xEF\xBB\xBF" "data: x\n\n", 1);
  ASSERT_EQ(ev.size(), 1u);
  EXPECT_EQ(ev[0].data, "x");
}

}  // namespace
