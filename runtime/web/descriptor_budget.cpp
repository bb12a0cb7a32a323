#include "runtime/web/descriptor_budget.hpp"

#include <sys/resource.h>

#include <algorithm>

namespace syncplc::web {

std::size_t raise_descriptor_limit() {
  rlimit r{};
  if (getrlimit(RLIMIT_NOFILE, &r) != 0) return 1024;
  if (r.rlim_cur < r.rlim_max) {
    rlimit raised = r;
    raised.rlim_cur = r.rlim_max;
    if (setrlimit(RLIMIT_NOFILE, &raised) == 0) r = raised;
  }
  // RLIM_INFINITY (never so on Linux for NOFILE, but a value all the same)
  return r.rlim_cur == RLIM_INFINITY ? std::size_t{1} << 20 : static_cast<std::size_t>(r.rlim_cur);
}

std::size_t http_connection_budget(std::size_t wanted, std::size_t open_limit) {
  const std::size_t shared = open_limit > kDescriptorsReserved ? open_limit - kDescriptorsReserved : 0;
  return std::max<std::size_t>(1, std::min(wanted, shared / 2));
}

}  // namespace syncplc::web
