// Reads a YAML file into a ConfigNode tree with file:line:col on every node.
#pragma once

#include <string>

#include "runtime/core/config_node.hpp"
#include "runtime/project/diagnostics.hpp"

namespace syncplc {

// Returns a Null node and records a diagnostic when the file cannot be read
// or parsed. Duplicate keys in a map are errors.
ConfigNode read_yaml_file(const std::string& path, Diagnostics& diags);
ConfigNode read_yaml_string(const std::string& text, const std::string& name, Diagnostics& diags);

}  // namespace syncplc
