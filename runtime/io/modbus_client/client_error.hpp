// What went wrong with one exchange of the Modbus TCP client driver: the
// value of a request group's `<group>_error` status channel (UINT) and the
// `value` of its fault events. 1..255 are the exception codes a device
// answered with (Modbus Application Protocol v1.1b3 §7); from 256 on, the
// client's own findings. docs/modbus-client.md lists them.
#pragma once

#include <cstdint>
#include <string_view>

namespace syncplc {

enum class ClientError : std::uint16_t {
  None = 0,
  // 1..255: an exception reply with this exception code
  Timeout = 256,          // no whole reply within the response timeout
  ConnectFailed = 257,    // the TCP connection could not be set up (refused, unreachable, connect timeout)
  ConnectionLost = 258,   // the device closed the connection, or sending failed
  NotConnected = 259,     // another group's failure closed the connection; waiting to reconnect
  Short = 260,            // the reply ends before what its function needs (or the connection closed mid-reply)
  Oversized = 261,        // the reply is longer than its function allows (or its length field exceeds 260 bytes)
  Malformed = 262,        // not Modbus TCP: protocol id not 0, length field inconsistent with the frame
  WrongTransaction = 263, // the reply's transaction id is not the request's
  WrongUnit = 264,        // the reply's unit id is not the request's
  WrongFunction = 265,    // the reply's function code is neither the request's nor its exception
  WrongByteCount = 266,   // a read reply's byte count is not what the request's quantity needs
  WrongEcho = 267,        // a write reply does not echo the request's address, quantity or value
  NoReply = 268,          // nothing exchanged yet (the first request has not completed)
};

inline constexpr std::uint16_t code(ClientError e) { return static_cast<std::uint16_t>(e); }
inline constexpr ClientError exception_error(std::uint8_t exception_code) { return static_cast<ClientError>(exception_code); }

// Whether the connection is kept after this error: only an exception reply
// (a well-formed answer) keeps it; every other failure leaves the byte stream
// in an unknown state (a late reply could be taken for the next), so the
// connection is closed and opened again.
inline constexpr bool keeps_connection(std::uint16_t c) { return c == 0 || (c >= 1 && c <= 255); }

// Short names: "timeout", "exception 02 illegal data address", ...
std::string_view client_error_name(std::uint16_t code);
// A small index for per-class tables (event texts): 0 none, 1..kErrorSlots-1.
std::size_t client_error_slot(std::uint16_t code);
inline constexpr std::size_t kErrorSlots = 25;
std::uint16_t client_error_of_slot(std::size_t slot);  // a representative code of the slot

}  // namespace syncplc
