// Server-Sent Events (the HTML standard's text/event-stream) read from the
// bytes of a stream as they arrive, in chunks cut anywhere: a line may end
// in LF, CRLF or CR (a CRLF cut between two chunks is one line end), a line
// starting with ':' is a comment (servers send them to keep a connection
// alive), data lines of one event are joined with '\n', and an event is
// dispatched by the empty line after it. `syncplc watch` reads GET /stream
// with it (docs/http-api.md). Pure: no I/O, tested on its own.
#pragma once

#include <string>
#include <string_view>
#include <vector>

namespace syncplc::cli {

struct SseEvent {
  std::string type = "message";  // the "event:" field; "message" without one
  std::string data;              // the "data:" lines joined with '\n'
  std::string id;                // the last "id:" seen on the stream
};

class SseReader {
 public:
  // The events the bytes complete, in order; what is left waits for more.
  std::vector<SseEvent> feed(std::string_view bytes);

 private:
  void line(std::string_view l, std::vector<SseEvent>& out);

  std::string partial_;         // a line not ended yet
  bool after_cr_ = false;       // the last byte ended a line with CR: a LF next is part of it
  bool started_ = false;        // past a leading byte-order mark
  std::string type_, data_, last_id_;
  bool has_data_ = false;
};

}  // namespace syncplc::cli
