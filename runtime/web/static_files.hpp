// The HMI's files (hmi_web/dist) as the HTTP server serves them: only
// regular files under the directory (no "..", no symbolic link out of it),
// a directory as its index.html, each with its MIME type.
#pragma once

#include <string>

#include "runtime/web/http/message.hpp"

namespace syncplc::web {

class StaticFiles {
 public:
  // `root` must hold index.html; false otherwise (nothing is served then).
  bool open(const std::string& root);
  // Answers a GET or HEAD of `path` (decoded): true with the file in `res`,
  // false when there is no such file here.
  bool serve(const std::string& path, http::Response& res) const;
  static std::string mime_type(const std::string& path);

 private:
  std::string root_;  // real path, no trailing slash
};

}  // namespace syncplc::web
