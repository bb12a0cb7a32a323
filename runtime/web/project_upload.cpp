#include "runtime/web/project_upload.hpp"

#include <stdlib.h>
#include <sys/stat.h>

#include <filesystem>
#include <set>

#include "runtime/project/inside_dir.hpp"
#include "runtime/project/yaml_tree.hpp"
#include "runtime/store/project_store.hpp"

namespace syncplc::web {
namespace fs = std::filesystem;

namespace {

// Plain relative names only: letters, digits, _ - . and / between parts,
// no part "." or "..", at most 255 bytes; .yaml, .yml, .csv or .st (Structured Text).
bool good_name(const std::string& n, std::string* why) {
  if (n.empty() || n.size() > 255) {
    *why = "a file name must be 1..255 bytes";
    return false;
  }
  for (char ch : n)
    if (!(std::isalnum(static_cast<unsigned char>(ch)) || ch == '_' || ch == '-' || ch == '.' || ch == '/')) {
      *why = "'" + n + "': file names may hold letters, digits, _ - . and / only";
      return false;
    }
  if (n.find("//") != std::string::npos || n.back() == '/') {
    *why = "'" + n + "': an empty part in a file name";
    return false;
  }
  if (n.front() == '/') {
    *why = "'" + n + "': name files relative to the project's directory";
    return false;
  }
  for (const auto& part : fs::path(n))
    if (part == ".." || part == "." || part.empty()) {
      *why = "'" + n + "': a name may not leave the project's directory or hold '.' or '..'";
      return false;
    }
  const std::string ext = fs::path(n).extension().string();
  if (ext != ".yaml" && ext != ".yml" && ext != ".csv" && ext != ".st") {
    *why = "'" + n + "': a project holds .yaml, .yml, .csv and .st files only";
    return false;
  }
  return true;
}

// `dir` "" (a reload or rollback of the instance's own file): nothing to
// strip; its prefix would be "/", and every slash of the path would go.
std::string strip_dir(const std::string& text, const std::string& dir) {
  std::string out = text;
  if (dir.empty()) return out;
  const std::string prefix = dir + "/";
  for (std::size_t at = out.find(prefix); at != std::string::npos; at = out.find(prefix, at)) out.erase(at, prefix.size());
  return out;
}

// Every include: of every uploaded file names another uploaded file: the
// loader never opens anything outside the upload (not even to refuse it
// afterwards: /dev/zero, a FIFO, another project's secrets in its errors).
// A file that is not YAML is left to the loader, which says where.
nlohmann::json foreign_includes(const Upload& u) {
  nlohmann::json errors = nlohmann::json::array();
  std::set<std::string> names;
  for (const auto& f : u.files) names.insert(f.path);
  for (const auto& f : u.files) {
    const std::string ext = fs::path(f.path).extension().string();
    if (ext != ".yaml" && ext != ".yml") continue;
    Diagnostics diags;  // a file the loader cannot read is the loader's to report, with its place
    const ConfigNode root = read_yaml_string(f.text, f.path, diags);
    const ConfigNode* inc = diags.empty() && root.is_map() ? root.find("include") : nullptr;
    if (!inc) continue;
    std::vector<const ConfigNode*> items;
    if (inc->is_scalar()) items.push_back(inc);
    else if (inc->is_list())
      for (const auto& i : inc->items) items.push_back(&i);
    for (const ConfigNode* i : items) {
      if (!i->is_scalar()) continue;  // the loader's error
      const std::string& name = i->scalar;
      const fs::path p = fs::path(name).is_absolute() ? fs::path(name)
                                                      : (fs::path(f.path).parent_path() / name).lexically_normal();
      if (names.count(p.string())) continue;
      errors.push_back({{"where", i->loc.text()},
                        {"message", "include '" + name + "' is not among the files sent: send every file the project "
                                    "includes, named relative to the main file's directory"}});
    }
  }
  return errors;
}

}  // namespace

std::optional<Upload> parse_upload(const nlohmann::json& body, std::size_t max_files, std::string* error) {
  const auto main = body.find("main"), files = body.find("files");
  if (main == body.end() || !main->is_string() || files == body.end() || !files->is_object() || files->empty()) {
    *error = R"(expected {"main": "project.yaml", "files": {"project.yaml": "...", "include.yaml": "..."}})";
    return std::nullopt;
  }
  if (files->size() > max_files) {
    *error = "the upload holds " + std::to_string(files->size()) + " files; at most " + std::to_string(max_files) + " are taken";
    return std::nullopt;
  }
  const std::string main_name = main->get<std::string>();
  if (!files->contains(main_name)) {
    *error = "the main file '" + main_name + "' is not among the files sent";
    return std::nullopt;
  }
  Upload u;
  for (const auto& [name, text] : files->items()) {
    if (!good_name(name, error)) return std::nullopt;
    if (!text.is_string()) {
      *error = "'" + name + "': a file's content must be a JSON string";
      return std::nullopt;
    }
    store::SourceFile f{fs::path(name).lexically_normal().string(), text.get<std::string>()};
    if (name == main_name) u.files.insert(u.files.begin(), std::move(f));
    else u.files.push_back(std::move(f));
  }
  return u;
}

nlohmann::json error_json(const std::string& line, const std::string& dir) {
  const std::string text = strip_dir(line, dir);
  // "file:line:col: message"
  const auto a = text.find(':');
  const auto b = a == std::string::npos ? a : text.find(':', a + 1);
  const auto c = b == std::string::npos ? b : text.find(':', b + 1);
  if (c != std::string::npos && c + 1 < text.size() && text[c + 1] == ' ')
    return {{"where", text.substr(0, c)}, {"message", text.substr(c + 2)}};
  return {{"where", nullptr}, {"message", text}};
}

UploadCheck check_upload(const Upload& u, const std::string& root, const LoadOptions& options) {
  UploadCheck out;
  out.errors = foreign_includes(u);
  if (!out.errors.empty()) return out;
  std::error_code ec;
  fs::create_directories(root, ec);
  chmod(root.c_str(), 0700);
  std::string tmpl = root + "/check-XXXXXX";
  if (!mkdtemp(tmpl.data())) {
    out.errors.push_back({{"where", nullptr}, {"message", "cannot make a directory under " + root + " to check the upload"}});
    return out;
  }
  const std::string dir = tmpl;
  std::string error;
  const std::string main = store::extract_files(u.files, dir, &error);
  if (main.empty()) {
    out.errors.push_back({{"where", nullptr}, {"message", strip_dir(error, dir)}});
    fs::remove_all(dir, ec);
    return out;
  }
  const LoadResult r = load_project(main, options);
  for (const auto& d : r.diagnostics.sorted()) out.errors.push_back(error_json(d.text(), dir));
  for (const auto& s : r.sources) {
    std::string p;
    if (!resolves_inside(dir, s.path, &p))
      out.errors.push_back({{"where", nullptr},
                            {"message", "the project reads " + p + ", outside the upload: send every file it includes"}});
  }
  out.ok = out.errors.empty();
  if (out.ok) out.hash = store::make_content(r.sources).hash;
  fs::remove_all(dir, ec);
  return out;
}

std::string keep_upload(const Upload& u, const std::string& root, const std::string& hash, std::string* error) {
  return store::extract_files(u.files, root + "/" + hash, error);
}

}  // namespace syncplc::web
