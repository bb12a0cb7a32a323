// The one rule for "a project's file lies in its directory", for a project
// sent to the PLC from both ends: `syncplc load` collecting the files it
// sends (runtime/cli/project_upload.hpp) and the PLC checking an upload
// (runtime/web/project_upload.hpp). Paths are compared after every symbolic
// link is resolved: a name inside the directory that is a link to a file
// elsewhere (/etc/passwd, another project's secrets) is outside.
#pragma once

#include <filesystem>
#include <string>

namespace syncplc {

// Whether `file`, every symlink resolved, lies under `dir` (resolved too).
// `resolved` gets the path it resolves to (for the message). A file that
// does not exist is judged by what exists of its path.
bool resolves_inside(const std::filesystem::path& dir, const std::filesystem::path& file, std::string* resolved = nullptr);

}  // namespace syncplc
