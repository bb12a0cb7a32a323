#include "runtime/store/sqlite_result.hpp"

#include <sqlite3.h>

namespace syncplc::store {

SqliteTrouble classify(int extended_code) {
  switch (extended_code & 0xff) {  // the primary code is the low byte
    case SQLITE_BUSY:
    case SQLITE_LOCKED: return SqliteTrouble::Busy;
    case SQLITE_CORRUPT:
    case SQLITE_NOTADB: return SqliteTrouble::Corrupt;
    default: return SqliteTrouble::Other;
  }
}

std::string result_code_name(int extended_code) {
  struct Name {
    int code;
    const char* name;
  };
  // The primary codes, and the extended ones of the kinds the store decides on.
  static constexpr Name kNames[] = {
      {SQLITE_OK, "SQLITE_OK"},
      {SQLITE_ERROR, "SQLITE_ERROR"},
      {SQLITE_INTERNAL, "SQLITE_INTERNAL"},
      {SQLITE_PERM, "SQLITE_PERM"},
      {SQLITE_ABORT, "SQLITE_ABORT"},
      {SQLITE_BUSY, "SQLITE_BUSY"},
      {SQLITE_LOCKED, "SQLITE_LOCKED"},
      {SQLITE_NOMEM, "SQLITE_NOMEM"},
      {SQLITE_READONLY, "SQLITE_READONLY"},
      {SQLITE_INTERRUPT, "SQLITE_INTERRUPT"},
      {SQLITE_IOERR, "SQLITE_IOERR"},
      {SQLITE_CORRUPT, "SQLITE_CORRUPT"},
      {SQLITE_NOTFOUND, "SQLITE_NOTFOUND"},
      {SQLITE_FULL, "SQLITE_FULL"},
      {SQLITE_CANTOPEN, "SQLITE_CANTOPEN"},
      {SQLITE_PROTOCOL, "SQLITE_PROTOCOL"},
      {SQLITE_EMPTY, "SQLITE_EMPTY"},
      {SQLITE_SCHEMA, "SQLITE_SCHEMA"},
      {SQLITE_TOOBIG, "SQLITE_TOOBIG"},
      {SQLITE_CONSTRAINT, "SQLITE_CONSTRAINT"},
      {SQLITE_MISMATCH, "SQLITE_MISMATCH"},
      {SQLITE_MISUSE, "SQLITE_MISUSE"},
      {SQLITE_NOLFS, "SQLITE_NOLFS"},
      {SQLITE_AUTH, "SQLITE_AUTH"},
      {SQLITE_FORMAT, "SQLITE_FORMAT"},
      {SQLITE_RANGE, "SQLITE_RANGE"},
      {SQLITE_NOTADB, "SQLITE_NOTADB"},
      {SQLITE_NOTICE, "SQLITE_NOTICE"},
      {SQLITE_WARNING, "SQLITE_WARNING"},
      {SQLITE_BUSY_RECOVERY, "SQLITE_BUSY_RECOVERY"},
      {SQLITE_BUSY_SNAPSHOT, "SQLITE_BUSY_SNAPSHOT"},
      {SQLITE_BUSY_TIMEOUT, "SQLITE_BUSY_TIMEOUT"},
      {SQLITE_LOCKED_SHAREDCACHE, "SQLITE_LOCKED_SHAREDCACHE"},
      {SQLITE_LOCKED_VTAB, "SQLITE_LOCKED_VTAB"},
      {SQLITE_CORRUPT_VTAB, "SQLITE_CORRUPT_VTAB"},
      {SQLITE_CORRUPT_SEQUENCE, "SQLITE_CORRUPT_SEQUENCE"},
      {SQLITE_CORRUPT_INDEX, "SQLITE_CORRUPT_INDEX"},
      {SQLITE_READONLY_RECOVERY, "SQLITE_READONLY_RECOVERY"},
      {SQLITE_READONLY_CANTLOCK, "SQLITE_READONLY_CANTLOCK"},
      {SQLITE_READONLY_ROLLBACK, "SQLITE_READONLY_ROLLBACK"},
      {SQLITE_READONLY_DBMOVED, "SQLITE_READONLY_DBMOVED"},
      {SQLITE_READONLY_CANTINIT, "SQLITE_READONLY_CANTINIT"},
      {SQLITE_READONLY_DIRECTORY, "SQLITE_READONLY_DIRECTORY"},
      {SQLITE_CANTOPEN_ISDIR, "SQLITE_CANTOPEN_ISDIR"},
      {SQLITE_CANTOPEN_FULLPATH, "SQLITE_CANTOPEN_FULLPATH"},
      {SQLITE_CANTOPEN_SYMLINK, "SQLITE_CANTOPEN_SYMLINK"},
  };
  for (const auto& n : kNames)
    if (n.code == extended_code) return n.name;
  // An extended code not listed: its primary's name and the number.
  for (const auto& n : kNames)
    if (n.code == (extended_code & 0xff)) return std::string(n.name) + " (extended " + std::to_string(extended_code) + ")";
  return "SQLITE error " + std::to_string(extended_code);
}

std::string describe_result(int extended_code) {
  return std::string(sqlite3_errstr(extended_code)) + " (" + result_code_name(extended_code) + ")";
}

}  // namespace syncplc::store
