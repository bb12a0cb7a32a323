// Modbus TCP framing: the MBAP header (Modbus Messaging on TCP/IP
// Implementation Guide V1.0b, §3.1.3) in front of every request.
//
//   transaction id (2) | protocol id (2, always 0) | length (2) | unit id (1) | PDU
//
// `length` counts the unit id and the PDU, so a frame is 6 + length bytes,
// at most 260 (a PDU is at most 253 bytes). The server reads bytes as they
// come and asks check_frame whether a whole request is there yet; it never
// waits for the rest of a frame, so a client that stops half-way holds up
// nobody.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

namespace syncplc::modbus {

constexpr std::size_t kMbapLength = 7;      // header up to and including the unit id
constexpr std::size_t kMaxFrameLength = 260;
constexpr std::size_t kMaxPduLength = 253;

enum class FrameStatus : std::uint8_t {
  Incomplete,  // fewer bytes than the header announces: wait for more
  Complete,    // a whole frame of `length` bytes starts the buffer
  Bad,         // not Modbus TCP: the connection is closed (there is no frame to answer)
};

struct FrameCheck {
  FrameStatus status = FrameStatus::Incomplete;
  std::size_t length = 0;  // of the whole frame, when Complete
  std::string reason;      // when Bad
};

FrameCheck check_frame(const std::uint8_t* buf, std::size_t n);

inline std::uint16_t get_u16(const std::uint8_t* p) { return static_cast<std::uint16_t>((p[0] << 8) | p[1]); }

}  // namespace syncplc::modbus
