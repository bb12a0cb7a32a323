// The files of a project as `syncplc load` sends them to the PLC (POST
// /projects/load, docs/http-api.md): the main file and every file its
// `include:` lists name, followed recursively, each relative to the file
// that includes it (docs/project-format.md, "include"), and the Structured
// Text files their `sources:` name. Names are relative
// to the main file's directory, which is the upload's root on the PLC: a
// file outside it would have no name there, so it is refused here with the
// location of the include that names it; so is a name inside it that is a
// symbolic link to a file outside (runtime/project/inside_dir.hpp, the rule
// the PLC applies to an upload).
#pragma once

#include <map>
#include <optional>
#include <string>

namespace syncplc::cli {

struct ProjectUpload {
  std::string main;                           // the main file's name ("line.yaml")
  std::map<std::string, std::string> files;   // name ("parts/io.yaml") -> contents
};

// The project whose main file is `main_path`; nullopt with `error`
// ("line.yaml:3:12: include '../x.yaml' is outside ...") when a file cannot
// be read or lies outside. A file that is not valid YAML is sent as it is
// (the PLC's check reports where), without following its includes.
std::optional<ProjectUpload> collect_project(const std::string& main_path, std::string* error);

}  // namespace syncplc::cli
