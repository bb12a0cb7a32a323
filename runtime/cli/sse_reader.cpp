#include "runtime/cli/sse_reader.hpp"

namespace syncplc::cli {

std::vector<SseEvent> SseReader::feed(std::string_view bytes) {
  std::vector<SseEvent> out;
  if (!started_) {
    // A byte-order mark may open the stream; it may itself come in pieces.
    static constexpr std::string_view kBom = "\xEF\xBB\xBF";
    partial_.append(bytes);
    if (partial_.size() < kBom.size() && kBom.substr(0, partial_.size()) == partial_) return out;
    started_ = true;
    std::string first = std::move(partial_);
    partial_.clear();
    if (first.compare(0, kBom.size(), kBom) == 0) first.erase(0, kBom.size());
    return feed(first);
  }
  for (char c : bytes) {
    if (after_cr_) {
      after_cr_ = false;
      if (c == '\n') continue;  // the LF of a CRLF
    }
    if (c == '\r' || c == '\n') {
      after_cr_ = c == '\r';
      line(partial_, out);
      partial_.clear();
    } else {
      partial_ += c;
    }
  }
  return out;
}

void SseReader::line(std::string_view l, std::vector<SseEvent>& out) {
  if (l.empty()) {
    // The end of an event: dispatched when it had data, else forgotten.
    if (has_data_) {
      SseEvent e;
      if (!type_.empty()) e.type = type_;
      e.data = std::move(data_);
      e.id = last_id_;
      out.push_back(std::move(e));
    }
    type_.clear();
    data_.clear();
    has_data_ = false;
    return;
  }
  if (l.front() == ':') return;  // a comment
  const auto colon = l.find(':');
  std::string_view field = l.substr(0, colon);
  std::string_view value = colon == std::string_view::npos ? std::string_view() : l.substr(colon + 1);
  if (!value.empty() && value.front() == ' ') value.remove_prefix(1);
  if (field == "event") {
    type_ = value;
  } else if (field == "data") {
    if (has_data_) data_ += '\n';
    data_ += value;
    has_data_ = true;
  } else if (field == "id") {
    if (value.find('\0') == std::string_view::npos) last_id_ = value;
  }
  // "retry" and unknown fields: nothing to do for a reader that does not reconnect.
}

}  // namespace syncplc::cli
