// Where `syncplc run` finds the HMI's built files when --hmi-dir is not given.
// An installed syncplc (cmake --install, the Debian package) serves the copy
// installed beside it (PREFIX/share/syncplc/hmi for PREFIX/bin/syncplc); a
// developer's build serves the source tree's hmi_web/dist. Both are decided
// by the build (CMakeLists.txt: SYNCPLC_HMI_DIST, SYNCPLC_HMI_INSTALL_DIR);
// the choice between them is made at run time, so one binary does both and
// the package is made from the build tree's binary as it is (docs/deployment.md).
#pragma once

#include <filesystem>
#include <string>

namespace syncplc::web {

// The installed copy relative to the executable `exe` (`from_bin`: the
// install's data directory relative to its bin directory, "../share/syncplc/hmi")
// when it holds an index.html, else `build_dist`.
std::string hmi_dir_for(const std::filesystem::path& exe, const std::string& from_bin, const std::string& build_dist);

// hmi_dir_for this process's executable (/proc/self/exe) and the build's paths.
std::string default_hmi_dir();

}  // namespace syncplc::web
