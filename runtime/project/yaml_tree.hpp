// Reads a YAML file into a ConfigNode tree with file:line:col on every node.
#pragma once

#include <string>
#include <vector>

#include "runtime/core/config_node.hpp"
#include "runtime/project/diagnostics.hpp"
#include "runtime/store/source_file.hpp"

namespace syncplc {

// Returns a Null node and records a diagnostic when the file cannot be read
// or parsed. Duplicate keys in a map are errors. A file that was read is
// added to `read` (the project store keeps what the loader parsed).
ConfigNode read_yaml_file(const std::string& path, Diagnostics& diags, std::vector<store::SourceFile>* read = nullptr);
ConfigNode read_yaml_string(const std::string& text, const std::string& name, Diagnostics& diags);

}  // namespace syncplc
