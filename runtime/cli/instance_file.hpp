// How `syncplc reload` finds a running `syncplc run`: a pid file per running
// project, and beside it the outcome of the last reload.
//
// Default place: $XDG_RUNTIME_DIR/syncplc/ (else /tmp/syncplc-UID/, mode 0700),
// named after the project file's absolute path, so `syncplc reload FILE`
// finds the instance that runs FILE. Contents: the pid, then the project path.
#pragma once

#include <optional>
#include <string>

namespace syncplc::cli {

std::string runtime_dir();
std::string default_pid_file(const std::string& project);

struct InstanceFile {
  int pid = 0;
  std::string project;
};

// Writes the pid file (creating its directory); false with *error.
bool write_instance_file(const std::string& path, const std::string& project, std::string* error);
std::optional<InstanceFile> read_instance_file(const std::string& path, std::string* error);
// Where `run` writes the outcome of each reload: the pid file's path + ".reload".
inline std::string reload_result_file(const std::string& pid_file) { return pid_file + ".reload"; }

}  // namespace syncplc::cli
