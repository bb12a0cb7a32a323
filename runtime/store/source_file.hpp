// A file as the project loader read it: the path it opened and the bytes it
// parsed. The project store keeps exactly these bytes (not a second read of
// the disk, which may have changed since).
#pragma once

#include <string>

namespace syncplc::store {

struct SourceFile {
  std::string path;  // as opened (the loader's path; a stored version's: its name in the version)
  std::string text;
};

}  // namespace syncplc::store
