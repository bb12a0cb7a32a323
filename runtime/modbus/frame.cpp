#include "runtime/modbus/frame.hpp"

namespace syncplc::modbus {

FrameCheck check_frame(const std::uint8_t* buf, std::size_t n) {
  FrameCheck c;
  // Judge the header as soon as its fields are in: garbage is refused at its
  // fourth byte rather than after waiting for a length it made up.
  if (n >= 4) {
    const std::uint16_t protocol = get_u16(buf + 2);
    if (protocol != 0) {
      c.status = FrameStatus::Bad;
      c.reason = "protocol id " + std::to_string(protocol) + " is not 0 (Modbus)";
      return c;
    }
  }
  if (n < 6) return c;
  const std::uint16_t length = get_u16(buf + 4);
  if (length < 2 || length > kMaxPduLength + 1) {
    c.status = FrameStatus::Bad;
    c.reason = "length field " + std::to_string(length) + " outside 2..254";
    return c;
  }
  if (n < 6u + length) return c;
  c.status = FrameStatus::Complete;
  c.length = 6u + length;
  return c;
}

}  // namespace syncplc::modbus
