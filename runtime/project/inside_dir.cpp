#include "runtime/project/inside_dir.hpp"

namespace syncplc {
namespace fs = std::filesystem;

bool resolves_inside(const fs::path& dir, const fs::path& file, std::string* resolved) {
  std::error_code ec;
  const fs::path d = fs::weakly_canonical(fs::absolute(dir, ec), ec);
  const fs::path f = fs::weakly_canonical(fs::absolute(file, ec), ec);
  if (resolved) *resolved = f.string();
  if (ec) return false;  // a path that cannot be resolved is not known to be inside
  // Component by component: /a/bc is not inside /a/b.
  auto di = d.begin(), fi = f.begin();
  for (; di != d.end(); ++di, ++fi) {
    if (di->empty()) continue;  // the trailing "" of "/a/b/"
    if (fi == f.end() || *di != *fi) return false;
  }
  return true;
}

}  // namespace syncplc
