#include "runtime/cli/instance_file.hpp"

#include <sys/stat.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <functional>

namespace syncplc::cli {

std::string runtime_dir() {
  if (const char* x = std::getenv("XDG_RUNTIME_DIR"); x && *x) return std::string(x) + "/syncplc";
  return "/tmp/syncplc-" + std::to_string(getuid());
}

std::string default_pid_file(const std::string& project) {
  std::error_code ec;
  std::string abs = std::filesystem::weakly_canonical(std::filesystem::absolute(project, ec), ec).string();
  std::string stem = std::filesystem::path(project).stem().string();
  char hash[17];
  std::snprintf(hash, sizeof hash, "%016zx", std::hash<std::string>{}(abs));
  return runtime_dir() + "/" + stem + "-" + hash + ".pid";
}

bool write_instance_file(const std::string& path, const std::string& project, std::string* error) {
  std::error_code ec;
  auto dir = std::filesystem::path(path).parent_path();
  if (!dir.empty()) {
    std::filesystem::create_directories(dir, ec);
    if (dir.string() == runtime_dir()) chmod(dir.c_str(), 0700);  // only its owner may signal through it
  }
  std::ofstream f(path, std::ios::trunc);
  if (!f) {
    if (error) *error = "cannot write the pid file " + path;
    return false;
  }
  std::string abs = std::filesystem::weakly_canonical(std::filesystem::absolute(project, ec), ec).string();
  f << getpid() << "\n" << abs << "\n";
  return static_cast<bool>(f);
}

std::optional<InstanceFile> read_instance_file(const std::string& path, std::string* error) {
  std::ifstream f(path);
  InstanceFile i;
  if (!f || !(f >> i.pid) || i.pid <= 0) {
    if (error) *error = "no running `syncplc run` found (no pid file " + path + ")";
    return std::nullopt;
  }
  std::getline(f >> std::ws, i.project);
  // The process must still be there and be syncplc (a stale file after a crash is not).
  std::ifstream comm("/proc/" + std::to_string(i.pid) + "/comm");
  std::string name;
  if (!comm || !(comm >> name) || name != "syncplc") {
    if (error) *error = "the pid file " + path + " names process " + std::to_string(i.pid) + ", which is not a running syncplc";
    return std::nullopt;
  }
  return i;
}

}  // namespace syncplc::cli
