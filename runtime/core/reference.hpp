// References to values in a project, as users write them in connections,
// traces, watch lists, metrics and scan-cycle tests: "tag", "tag[i]",
// "instance.pin", "instance.pin[i]". The one parser of that syntax and the
// messages for what it can refer to, shared by the loader (names being
// declared) and Program::resolve (a loaded program), so both say the same.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include "runtime/core/block.hpp"

namespace syncplc {

struct Reference {
  std::string text;    // trimmed
  std::string base;    // text without the index: "tag" or "instance.pin"
  std::string owner;   // "instance" of "instance.pin"; the tag name otherwise
  std::string member;  // "pin" of "instance.pin"; "" for a tag
  std::optional<std::int64_t> index;  // as written (tags: within their bounds; pins: 1..n)
  bool dotted() const { return !member.empty(); }
};

// Empty on success; otherwise the message ("bad array index in 'a[x]'").
std::optional<Reference> parse_reference(std::string_view text, std::string* error);

// The element `index` of an array that starts at `lower` and has `length`
// elements, 0-based; nullopt (with the message) when it is outside. Checked
// without overflow for any 64-bit index and bound.
std::optional<std::uint32_t> element_of(const Reference& r, std::int64_t lower, std::uint32_t length, std::string* error);

std::string unknown_instance_message(const std::string& instance);
std::string unknown_tag_message(const std::string& name);
// "block x (T) has no pin 'P' (IN, OUT)": the valid pins listed.
std::string no_pin_message(const std::string& instance, const BlockTypeInfo& type, const std::string& pin);
std::string pin_names(const BlockTypeInfo& type);

}  // namespace syncplc
