// A PM QoS CPU latency request (/dev/cpu_dma_latency): while it is held, idle
// CPUs stay out of idle states whose exit latency exceeds the value, so a
// task's wake-up is not delayed by a deep C-state. cyclictest holds 0 by
// default; so does `syncplc run` (bench/rt_jitter measures the difference).
// It costs power: idle CPUs poll instead of halting.
#pragma once

#include <string>

namespace syncplc {

class CpuLatencyRequest {
 public:
  CpuLatencyRequest() = default;
  CpuLatencyRequest(const CpuLatencyRequest&) = delete;
  CpuLatencyRequest& operator=(const CpuLatencyRequest&) = delete;
  ~CpuLatencyRequest() { release(); }

  // Holds the request at `us` microseconds until release(). False with the
  // reason when the device cannot be opened or written (not root, no device).
  bool hold(int us, std::string* error);
  void release();
  bool held() const { return fd_ >= 0; }

 private:
  int fd_ = -1;
};

}  // namespace syncplc
