// `syncplc reload [PROJECT] [--pid-file F] [--version N]`: asks the running
// `syncplc run` of PROJECT to load its project file again (online change),
// or with --version a version from its project store (rollback), waits for
// the outcome and prints it. Exit 0: accepted; 1: rejected (the running program
// goes on unchanged); 2: no such instance. With an API URL (--url, or
// $SYNCPLC_URL when no PROJECT or --pid-file names a local instance) it
// asks the PLC at that URL instead (cmd_load.cpp), with the same statuses.
#include <signal.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>
#include <thread>

#include "runtime/cli/commands.hpp"
#include "runtime/cli/instance_file.hpp"
#include "runtime/plc/project_versions.hpp"

namespace syncplc::cli {
using namespace plc;  // the PLC instance's database paths and stored versions (runtime/plc)


int cmd_reload(const std::string& project, const std::string& pid_file, std::int64_t version,
               const OnlineOptions& online) {
  if (!online.url.empty() && (!project.empty() || !pid_file.empty())) {
    std::cerr << "syncplc: reload: --url reloads the project file of the PLC at that URL; name no PROJECT or "
                 "--pid-file with it (syncplc load PROJECT sends another file)\n";
    return kExitInvalid;
  }
  if (!online.url.empty() || (project.empty() && pid_file.empty() && api_url_given("")))
    return reload_through_api(version, online);
  std::string path = pid_file;
  if (path.empty() && !project.empty()) path = default_pid_file(project);
  if (path.empty()) {
    // The only instance running, if there is exactly one.
    std::error_code ec;
    int found = 0;
    for (const auto& e : std::filesystem::directory_iterator(runtime_dir(), ec))
      if (e.path().extension() == ".pid" && read_instance_file(e.path().string(), nullptr)) {
        path = e.path().string();
        ++found;
      }
    if (found != 1) {
      std::cerr << "syncplc: reload: " << (found ? "several instances run: name the project file"
                                                 : "no running `syncplc run` found in " + runtime_dir())
                << "\n";
      return kExitInvalid;
    }
  }
  std::string err;
  auto inst = read_instance_file(path, &err);
  if (!inst) {
    std::cerr << "syncplc: reload: " << err << "\n";
    return kExitInvalid;
  }
  const std::string result = reload_result_file(path);
  std::error_code ec;
  std::filesystem::remove(result, ec);  // `run` writes it anew (write and rename) when the reload is done
  std::filesystem::remove(reload_request_file(path), ec);
  if (version > 0 && !write_reload_request(path, version, &err)) {
    std::cerr << "syncplc: reload: " << err << "\n";
    return kExitInvalid;
  }
  if (kill(inst->pid, SIGUSR1) != 0) {
    std::cerr << "syncplc: reload: cannot signal process " << inst->pid << "\n";
    return kExitInvalid;
  }
  // The change is done when every task has reached its switch: up to three
  // periods of the slowest task.
  for (int i = 0; i < 1200; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    std::ifstream f(result);
    if (!f) continue;
    std::stringstream text;
    text << f.rdbuf();
    std::string s = text.str();
    std::cout << s;
    return s.rfind("accepted", 0) == 0 ? kExitOk : kExitTestFailed;
  }
  std::cerr << "syncplc: reload: no answer from process " << inst->pid << " within 60 s\n";
  return kExitInvalid;
}

}  // namespace syncplc::cli
