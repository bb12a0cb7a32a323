// A project sent over HTTP (POST /projects/check and /load): its main file
// and includes as text. Checked like any untrusted input: names that stay
// inside the upload, a size and a file count within limits, then loaded by
// the one project loader, its errors named by the uploaded file names.
#pragma once

#include <nlohmann/json.hpp>

#include <string>
#include <vector>

#include "runtime/project/loader.hpp"
#include "runtime/store/source_file.hpp"

namespace syncplc::web {

struct Upload {
  std::vector<store::SourceFile> files;  // the main file first; paths relative to the project's directory
};

// From {"main": "a.yaml", "files": {"a.yaml": "…", …}}; nullopt with `error`
// naming what is wrong (a missing main file, a name that leaves the project,
// too many files).
std::optional<Upload> parse_upload(const nlohmann::json& body, std::size_t max_files, std::string* error);

struct UploadCheck {
  bool ok = false;
  nlohmann::json errors = nlohmann::json::array();  // [{"where": "a.yaml:12:7", "message"}]
  std::string hash;                                  // the project store's content hash (ok)
};

// Writes the upload under a fresh directory of `root`, loads it with
// `options` (nothing runs, no driver opens) and removes it again. Errors
// name the uploaded files ("a.yaml:12:7"); a project that reads a file
// outside the upload (an include with ../) is refused.
UploadCheck check_upload(const Upload& u, const std::string& root, const LoadOptions& options);

// Writes the upload to root/<hash>/ to load it by online change; the main
// file's path, or "" with `error`.
std::string keep_upload(const Upload& u, const std::string& root, const std::string& hash, std::string* error);

// "/…/uploads/abc/a.yaml:12:7: message" → {"where": "a.yaml:12:7", "message"}.
nlohmann::json error_json(const std::string& line, const std::string& dir);

}  // namespace syncplc::web
