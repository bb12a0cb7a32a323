#include "runtime/web/hmi_location.hpp"

#include <system_error>

namespace syncplc::web {

std::string hmi_dir_for(const std::filesystem::path& exe, const std::string& from_bin, const std::string& build_dist) {
  if (!exe.empty() && !from_bin.empty()) {
    const auto installed = (exe.parent_path() / from_bin).lexically_normal();
    std::error_code ec;
    if (std::filesystem::is_regular_file(installed / "index.html", ec)) return installed.string();
  }
  return build_dist;
}

std::string default_hmi_dir() {
  std::error_code ec;
  // The real executable, every symlink resolved: a link to the binary in
  // another directory still finds the files installed beside the binary.
  const auto exe = std::filesystem::read_symlink("/proc/self/exe", ec);
  return hmi_dir_for(ec ? std::filesystem::path() : exe, SYNCPLC_HMI_FROM_BIN, SYNCPLC_HMI_DIST);
}

}  // namespace syncplc::web
