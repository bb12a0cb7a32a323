#include "runtime/web/static_files.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <climits>
#include <cstdlib>
#include <string_view>
#include <utility>

namespace syncplc::web {
namespace {

// The files the HMI's build makes, and what browsers need told.
constexpr std::pair<std::string_view, std::string_view> kTypes[] = {
    {"html", "text/html"},        {"htm", "text/html"},          {"js", "text/javascript"},
    {"mjs", "text/javascript"},   {"css", "text/css"},           {"json", "application/json"},
    {"map", "application/json"},  {"svg", "image/svg+xml"},      {"png", "image/png"},
    {"jpg", "image/jpeg"},        {"jpeg", "image/jpeg"},        {"gif", "image/gif"},
    {"ico", "image/x-icon"},      {"webp", "image/webp"},        {"woff", "font/woff"},
    {"woff2", "font/woff2"},      {"ttf", "font/ttf"},           {"txt", "text/plain"},
    {"wasm", "application/wasm"}, {"webmanifest", "application/manifest+json"},
};

// A path that stays inside the root: every segment a plain name.
bool plain_segments(const std::string& path) {
  if (path.empty() || path.front() != '/') return false;
  std::size_t at = 1;
  while (at <= path.size()) {
    const std::size_t slash = std::min(path.find('/', at), path.size());
    const std::string_view seg(path.data() + at, slash - at);
    if (seg == "." || seg == "..") return false;
    if (seg.find('\\') != std::string_view::npos || seg.find('\0') != std::string_view::npos) return false;
    at = slash + 1;
  }
  return true;
}

}  // namespace

bool StaticFiles::open(const std::string& root) {
  char real[PATH_MAX];
  struct stat st;
  if (!realpath(root.c_str(), real) || stat((std::string(real) + "/index.html").c_str(), &st) != 0) return false;
  root_ = real;
  return true;
}

std::string StaticFiles::mime_type(const std::string& path) {
  const std::size_t dot = path.rfind('.');
  if (dot == std::string::npos || path.find('/', dot) != std::string::npos) return "application/octet-stream";
  const std::string_view ext(path.data() + dot + 1, path.size() - dot - 1);
  for (const auto& [e, type] : kTypes)
    if (e == ext) return std::string(type);
  return "application/octet-stream";
}

bool StaticFiles::serve(const std::string& path, http::Response& res) const {
  if (root_.empty() || !plain_segments(path)) return false;
  std::string file = root_ + path;
  struct stat st;
  if (stat(file.c_str(), &st) == 0 && S_ISDIR(st.st_mode)) file += (file.back() == '/' ? "" : "/") + std::string("index.html");
  // A symbolic link may point anywhere: the real path must still be in the root.
  char real[PATH_MAX];
  if (!realpath(file.c_str(), real)) return false;
  const std::string r = real;
  if (r.compare(0, root_.size(), root_) != 0 || (r.size() > root_.size() && r[root_.size()] != '/')) return false;
  const int fd = ::open(real, O_RDONLY | O_CLOEXEC);
  if (fd < 0) return false;
  std::string body;
  if (fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
    ::close(fd);
    return false;
  }
  body.resize(static_cast<std::size_t>(st.st_size));
  std::size_t got = 0;
  while (got < body.size()) {
    const ssize_t n = ::read(fd, body.data() + got, body.size() - got);
    if (n <= 0) break;
    got += static_cast<std::size_t>(n);
  }
  ::close(fd);
  body.resize(got);
  res.status = 200;
  res.set_content(std::move(body), mime_type(r));
  return true;
}

}  // namespace syncplc::web
