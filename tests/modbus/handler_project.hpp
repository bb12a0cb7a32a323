// The project the Modbus request handler is tested and fuzzed against: two
// tasks, so requests can span owners; every table and width; read-only and
// readwrite tags; explicit places for the 8-bit types; echo blocks that copy
// written tags to read-only ones; a tag the program writes every scan
// (forced: read-only to clients, since a readwrite tag a block writes is a load
// error); trim (main) beside big (slow) in holding registers
// 4100..4107, so one write can span both tasks; sp has engineering
// limits (-1000..1000). Only IEC blocks, so the fuzzer (which has
// no test blocks) loads it too.
#pragma once

namespace syncplc::testing {

inline constexpr const char* kHandlerProject = R"(
tasks:
  - {name: main, period: 1ms}
  - {name: slow, period: 10ms, write_queue: 16}
tags:
  - {name: run, type: BOOL, address: "%QX0.0", hmi: readwrite}
  - {name: lamps, type: "ARRAY[0..9] OF BOOL", address: "%QX0.1", hmi: readwrite, init: TRUE}
  - {name: fault, type: BOOL, address: "%QX2.0", hmi: read, init: TRUE}
  - {name: button, type: BOOL, address: "%IX0.0", hmi: read, init: TRUE}
  - {name: level, type: INT, address: "%IW7", hmi: read, init: -2}
  - {name: sp, type: INT, address: "%QW2", hmi: readwrite, init: 7, min: -1000, max: 1000}
  - {name: sp_echo, type: INT, address: "%QW3", hmi: read}
  - {name: small, type: SINT, hmi: readwrite, modbus: {table: holding_register, address: 100}}
  - {name: octet, type: BYTE, hmi: readwrite, modbus: {table: holding_register, address: 101}}
  - {name: pos, type: REAL, address: "%MD0", hmi: readwrite, init: 1.0}
  - {name: pos_echo, type: REAL, address: "%MD1", hmi: read}
  - {name: count, type: DINT, address: "%MD2", hmi: read, init: -2}
  - {name: big, type: LREAL, address: "%ML2", hmi: readwrite, init: 1.5, task: slow}
  - {name: when, type: TIME, address: "%ML3", hmi: readwrite, task: slow}
  - {name: trim, type: LREAL, hmi: readwrite, task: main, modbus: {table: holding_register, address: 4100}}
  - {name: forced, type: INT, address: "%QW4", hmi: read}
blocks:
  - {name: e1, type: MOVE, datatype: INT, task: main}
  - {name: e2, type: MOVE, datatype: REAL, task: main}
  - {name: force, type: MOVE, datatype: INT, task: main, inputs: {IN: 42}}
connections:
  - force.OUT -> forced
  - sp -> e1.IN
  - e1.OUT -> sp_echo
  - pos -> e2.IN
  - e2.OUT -> pos_echo
)";

}  // namespace syncplc::testing
