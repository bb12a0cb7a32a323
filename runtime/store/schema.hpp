// Each part of the store (retain, projects, events, trends) keeps its own
// tables and its own schema version in the table `schema`, so the parts
// evolve independently. A part lists its migrations in order; opening the
// database runs the ones past the stored version, each in one transaction.
// A database written by a newer syncplc (a version past the list) is refused
// for that part rather than misread.
#pragma once

#include <SQLiteCpp/Database.h>

#include <string>
#include <vector>

namespace syncplc::store {

struct SchemaPart {
  std::string name;                    // "events", "retain", ...
  std::vector<std::string> migrations;  // SQL; migrations[i] takes version i to i + 1
};

// Brings `part` up to date. False with `error` when the stored version is
// newer than this program knows; throws SQLite::Exception on SQL failure.
bool ensure_schema(SQLite::Database& db, const SchemaPart& part, std::string* error);
// The stored version of a part (0: none yet).
int schema_version(SQLite::Database& db, const std::string& part);

}  // namespace syncplc::store
