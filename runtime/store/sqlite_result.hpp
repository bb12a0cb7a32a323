// SQLite's result codes as the store tells them apart (sqlite.org, "Result
// and Error Codes"): a database another connection holds (BUSY, LOCKED) is
// waited for and never taken for damage; a damaged one (CORRUPT, NOTADB) is
// moved aside; anything else (CANTOPEN, IOERR, PERM, READONLY, FULL, ...) is
// an error that leaves the file alone. Decided on the extended code, named
// in messages by SQLite's own names ("SQLITE_BUSY_RECOVERY").
#pragma once

#include <string>

namespace syncplc::store {

enum class SqliteTrouble {
  Busy,     // SQLITE_BUSY, SQLITE_LOCKED and their extended codes
  Corrupt,  // SQLITE_CORRUPT, SQLITE_NOTADB and their extended codes
  Other,
};
SqliteTrouble classify(int extended_code);

// "SQLITE_BUSY", "SQLITE_CORRUPT_INDEX"; "SQLITE error 1234" for a code
// this build does not name.
std::string result_code_name(int extended_code);

// "database is locked (SQLITE_BUSY)": SQLite's text for the code and its name.
std::string describe_result(int extended_code);

}  // namespace syncplc::store
