#include "runtime/core/cpu_latency.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstdint>
#include <cstring>

namespace syncplc {

bool CpuLatencyRequest::hold(int us, std::string* error) {
  release();
  int fd = ::open("/dev/cpu_dma_latency", O_RDWR | O_CLOEXEC);
  if (fd < 0) {
    if (error) *error = std::strerror(errno);
    return false;
  }
  std::int32_t v = us;  // the kernel takes a binary s32 (or a hex string)
  if (::write(fd, &v, sizeof v) != static_cast<ssize_t>(sizeof v)) {
    if (error) *error = std::strerror(errno);
    ::close(fd);
    return false;
  }
  fd_ = fd;  // the request lasts as long as the file stays open
  return true;
}

void CpuLatencyRequest::release() {
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
}

}  // namespace syncplc
