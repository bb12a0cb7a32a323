// The Modbus keys of a project file, checked as the loader reads them: the
// `modbus:` section (the server's settings) and a tag's `modbus: {table,
// address}` (its explicit place). docs/project-format.md lists the keys and
// their ranges; docs/modbus.md what they mean for a client.
#pragma once

#include <optional>
#include <vector>

#include "runtime/core/config_node.hpp"
#include "runtime/modbus/modbus_config.hpp"
#include "runtime/core/program.hpp"
#include "runtime/project/diagnostics.hpp"

namespace syncplc {

// Fills `out` from the `modbus:` section; every wrong key or value is an error at its place.
void read_modbus_section(const ConfigNode& n, ModbusConfig& out, Diagnostics& d);

// A tag's explicit place. `tag` has its name, type, length and hmi access read.
// Nullopt, after reporting why, when the place is wrong for the tag.
std::optional<ModbusPlace> read_modbus_place(const ConfigNode& n, const Tag& tag, Diagnostics& d);

// Reports tags whose Modbus places share a coil or register, at the explicit
// place to blame (`place_loc`, by tag) and naming the other tag.
void check_modbus_overlaps(const std::vector<Tag>& tags, const ModbusPlaces& places, const std::vector<SourceLoc>& place_loc,
                           Diagnostics& d);

// The most values one Modbus request can queue to each task: its writable
// coils up to 1968 (FC 15), its writable holding-register values up to 123
// (FC 16). A request's writes to a task are queued and applied together, in
// one scan, so the task's write queue must hold that many. `tags` have their
// owners; the result has one entry per task.
std::vector<std::size_t> largest_modbus_writes(const std::vector<Tag>& tags, const ModbusPlaces& places, std::size_t tasks);

}  // namespace syncplc
