#include "runtime/store/schema.hpp"

#include <SQLiteCpp/Statement.h>
#include <SQLiteCpp/Transaction.h>

namespace syncplc::store {
namespace {

void ensure_schema_table(SQLite::Database& db) {
  db.exec("CREATE TABLE IF NOT EXISTS schema (part TEXT PRIMARY KEY, version INTEGER NOT NULL)");
}

}  // namespace

int schema_version(SQLite::Database& db, const std::string& part) {
  if (!db.tableExists("schema")) return 0;
  SQLite::Statement q(db, "SELECT version FROM schema WHERE part = ?");
  q.bind(1, part);
  return q.executeStep() ? q.getColumn(0).getInt() : 0;
}

bool ensure_schema(SQLite::Database& db, const SchemaPart& part, std::string* error) {
  ensure_schema_table(db);
  const int have = schema_version(db, part.name);
  const int want = static_cast<int>(part.migrations.size());
  if (have > want) {
    *error = "the database's " + part.name + " tables are version " + std::to_string(have) +
             ", newer than this syncplc knows (" + std::to_string(want) + ")";
    return false;
  }
  for (int v = have; v < want; ++v) {
    SQLite::Transaction t(db);
    db.exec(part.migrations[static_cast<std::size_t>(v)]);
    SQLite::Statement up(db, "INSERT INTO schema (part, version) VALUES (?, ?) "
                             "ON CONFLICT (part) DO UPDATE SET version = excluded.version");
    up.bind(1, part.name);
    up.bind(2, v + 1);
    up.exec();
    t.commit();
  }
  return true;
}

}  // namespace syncplc::store
