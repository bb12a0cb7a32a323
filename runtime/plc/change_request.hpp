// An online change as asked for (`syncplc reload`, SIGHUP, the HTTP API)
// and as answered.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "runtime/core/program_change.hpp"

namespace syncplc::plc {

struct ChangeRequest {
  enum class Kind : std::uint8_t {
    Reload,    // the instance's project file again (or `path` when given)
    Rollback,  // version `version` of the project store (0: the last accepted one)
    Load,      // `path`: an uploaded project's main file
  };
  Kind kind = Kind::Reload;
  std::string path;
  std::int64_t version = 0;
  std::string by;  // " by eng from 127.0.0.1" for the project store and the event log; "" from the command line
};

struct ChangeResult {
  bool accepted = false;
  // Like HTTP: 200 accepted, 400 the project's errors, 409 refused by the
  // PLC's state (a scan that does not end, the PLC stopping, a version that
  // cannot be extracted).
  int status = 200;
  std::string summary;                    // one line
  std::vector<std::string> lines;         // the errors (refused) or the change report (accepted)
  std::vector<InstanceChange> instances;  // accepted: what became of each block instance
  std::string hash;                       // accepted: the project store's content hash of the new files
};

}  // namespace syncplc::plc
