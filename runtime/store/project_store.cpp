#include "runtime/store/project_store.hpp"

#include <SQLiteCpp/Statement.h>
#include <SQLiteCpp/Transaction.h>
#include <sodium.h>
#include <sys/stat.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <map>

#include "runtime/store/schema.hpp"

namespace syncplc::store {
namespace fs = std::filesystem;

namespace {

const SchemaPart kProjectsSchema{
    "projects",
    {
        // project_content: one row per distinct file set; project_files: its
        // files; project_versions: one row per load attempt (hash NULL when no
        // file could be read). errors: the diagnostics, one per line.
        "CREATE TABLE project_content (hash TEXT PRIMARY KEY, files INTEGER NOT NULL);"
        "CREATE TABLE project_files (hash TEXT NOT NULL REFERENCES project_content (hash), "
        "  ordinal INTEGER NOT NULL, name TEXT NOT NULL, data BLOB NOT NULL, PRIMARY KEY (hash, ordinal));"
        "CREATE TABLE project_versions (number INTEGER PRIMARY KEY AUTOINCREMENT, time_ns INTEGER NOT NULL, "
        "  origin TEXT NOT NULL, source TEXT NOT NULL, accepted INTEGER NOT NULL, project_name TEXT NOT NULL, "
        "  project_version TEXT NOT NULL, hash TEXT REFERENCES project_content (hash), errors TEXT NOT NULL);",
    }};

std::string sha256_hex(const std::vector<SourceFile>& files) {
  if (sodium_init() < 0) throw std::runtime_error("libsodium cannot be initialised");
  crypto_hash_sha256_state st;
  crypto_hash_sha256_init(&st);
  auto feed = [&](const std::string& s) {
    crypto_hash_sha256_update(&st, reinterpret_cast<const unsigned char*>(s.data()), s.size());
  };
  for (const auto& f : files) {
    feed(f.path);
    feed(std::string(1, '\0') + std::to_string(f.text.size()) + std::string(1, '\0'));
    feed(f.text);
  }
  unsigned char out[crypto_hash_sha256_BYTES];
  crypto_hash_sha256_final(&st, out);
  char hex[2 * crypto_hash_sha256_BYTES + 1];
  sodium_bin2hex(hex, sizeof hex, out, sizeof out);
  return hex;
}

std::vector<std::string> split_lines(const std::string& s) {
  std::vector<std::string> out;
  std::size_t start = 0;
  while (start < s.size()) {
    std::size_t nl = s.find('\n', start);
    if (nl == std::string::npos) nl = s.size();
    out.push_back(s.substr(start, nl - start));
    start = nl + 1;
  }
  return out;
}

constexpr const char* kVersionColumns =
    "SELECT v.number, v.time_ns, v.origin, v.source, v.accepted, v.project_name, v.project_version, "
    "coalesce(v.hash, ''), coalesce(c.files, 0), v.errors FROM project_versions v "
    "LEFT JOIN project_content c ON c.hash = v.hash ";

ProjectVersion version_of(SQLite::Statement& q) {
  ProjectVersion v;
  v.number = q.getColumn(0).getInt64();
  v.time_ns = q.getColumn(1).getInt64();
  v.origin = q.getColumn(2).getString();
  v.source = q.getColumn(3).getString();
  v.accepted = q.getColumn(4).getInt() != 0;
  v.project_name = q.getColumn(5).getString();
  v.project_version = q.getColumn(6).getString();
  v.hash = q.getColumn(7).getString();
  v.files = q.getColumn(8).getInt();
  v.errors = split_lines(q.getColumn(9).getString());
  return v;
}

std::optional<ProjectVersion> one_version(SQLite::Database& db, const std::string& where, std::int64_t arg) {
  if (schema_version(db, kProjectsSchema.name) == 0) return std::nullopt;
  SQLite::Statement q(db, std::string(kVersionColumns) + where);
  if (where.find('?') != std::string::npos) q.bind(1, arg);
  if (!q.executeStep()) return std::nullopt;
  return version_of(q);
}

}  // namespace

ProjectContent make_content(const std::vector<SourceFile>& read) {
  ProjectContent c;
  if (read.empty()) return c;
  // Absolute, normalised paths; a file included twice is kept once.
  std::vector<std::pair<fs::path, const SourceFile*>> abs;
  for (const auto& f : read) {
    std::error_code ec;
    fs::path p = fs::weakly_canonical(fs::absolute(f.path, ec), ec);
    if (std::none_of(abs.begin(), abs.end(), [&](const auto& a) { return a.first == p; })) abs.emplace_back(p, &f);
  }
  // The deepest directory holding them all.
  fs::path root = abs.front().first.parent_path();
  for (const auto& [p, f] : abs) {
    (void)f;
    while (!root.empty() && p.lexically_relative(root).string().rfind("..", 0) == 0) root = root.parent_path();
  }
  for (const auto& [p, f] : abs) c.files.push_back({p.lexically_relative(root).generic_string(), f->text});
  std::sort(c.files.begin() + 1, c.files.end(), [](const SourceFile& a, const SourceFile& b) { return a.path < b.path; });
  c.hash = sha256_hex(c.files);
  return c;
}

bool prepare_projects(SQLite::Database& db, std::string* error) { return ensure_schema(db, kProjectsSchema, error); }

std::int64_t record_load(SQLite::Database& db, const ProjectLoad& load) {
  SQLite::Transaction t(db);
  const ProjectContent& c = load.content;
  if (!c.hash.empty()) {
    SQLite::Statement have(db, "INSERT OR IGNORE INTO project_content (hash, files) VALUES (?, ?)");
    have.bind(1, c.hash);
    have.bind(2, static_cast<int>(c.files.size()));
    if (have.exec() == 1) {  // new content: its files too
      SQLite::Statement f(db, "INSERT INTO project_files (hash, ordinal, name, data) VALUES (?, ?, ?, ?)");
      for (std::size_t i = 0; i < c.files.size(); ++i) {
        f.bind(1, c.hash);
        f.bind(2, static_cast<int>(i));
        f.bind(3, c.files[i].path);
        f.bind(4, c.files[i].text.data(), static_cast<int>(c.files[i].text.size()));
        f.exec();
        f.reset();
      }
    }
  }
  std::string errors;
  for (const auto& e : load.errors) errors += e + "\n";
  SQLite::Statement v(db, "INSERT INTO project_versions (time_ns, origin, source, accepted, project_name, "
                          "project_version, hash, errors) VALUES (?, ?, ?, ?, ?, ?, ?, ?)");
  v.bind(1, load.time_ns);
  v.bind(2, load.origin);
  v.bind(3, load.source);
  v.bind(4, load.accepted ? 1 : 0);
  v.bind(5, load.project_name);
  v.bind(6, load.project_version);
  if (c.hash.empty()) v.bind(7);
  else v.bind(7, c.hash);
  v.bind(8, errors);
  v.exec();
  const std::int64_t number = db.getLastInsertRowid();
  t.commit();
  return number;
}

std::vector<ProjectVersion> list_versions(SQLite::Database& db) {
  std::vector<ProjectVersion> out;
  if (schema_version(db, kProjectsSchema.name) == 0) return out;
  SQLite::Statement q(db, std::string(kVersionColumns) + "ORDER BY v.number");
  while (q.executeStep()) out.push_back(version_of(q));
  return out;
}

std::optional<ProjectVersion> find_version(SQLite::Database& db, std::int64_t number) {
  return one_version(db, "WHERE v.number = ?", number);
}

std::optional<ProjectVersion> last_accepted(SQLite::Database& db) {
  return one_version(db, "WHERE v.accepted = 1 ORDER BY v.number DESC LIMIT 1", 0);
}

std::vector<SourceFile> version_files(SQLite::Database& db, std::int64_t number) {
  std::vector<SourceFile> out;
  if (schema_version(db, kProjectsSchema.name) == 0) return out;
  SQLite::Statement q(db, "SELECT f.name, f.data FROM project_versions v JOIN project_files f ON f.hash = v.hash "
                          "WHERE v.number = ? ORDER BY f.ordinal");
  q.bind(1, number);
  while (q.executeStep()) {
    const SQLite::Column data = q.getColumn(1);
    out.push_back({q.getColumn(0).getString(), std::string(static_cast<const char*>(data.getBlob()),
                                                           static_cast<std::size_t>(data.getBytes()))});
  }
  return out;
}

bool same_as_last_accepted(SQLite::Database& db, const std::string& content_hash) {
  auto v = last_accepted(db);
  return v && !content_hash.empty() && v->hash == content_hash;
}

std::string extract_files(const std::vector<SourceFile>& files, const std::string& dir, std::string* error) {
  if (files.empty()) {
    *error = "the version has no files";
    return "";
  }
  std::error_code ec;
  fs::remove_all(dir, ec);
  fs::create_directories(dir, ec);
  if (ec || chmod(dir.c_str(), 0700) != 0) {
    *error = "cannot create " + dir + (ec ? ": " + ec.message() : "");
    return "";
  }
  for (const auto& f : files) {
    const fs::path name = fs::path(f.path).lexically_normal();
    if (name.is_absolute() || name.empty() || name.begin()->string() == "..") {
      *error = "the stored file name '" + f.path + "' would leave " + dir;
      return "";
    }
    const fs::path p = fs::path(dir) / name;
    fs::create_directories(p.parent_path(), ec);
    std::ofstream out(p, std::ios::binary | std::ios::trunc);
    out.write(f.text.data(), static_cast<std::streamsize>(f.text.size()));
    if (!out.flush()) {
      *error = "cannot write " + p.string();
      return "";
    }
  }
  return (fs::path(dir) / files.front().path).lexically_normal().string();
}

}  // namespace syncplc::store
