// What `load`, `rollback` and `reload --url` print of the PLC's answer to
// a project change (POST /projects/load, /check, /reload, /rollback;
// docs/http-api.md): the change report of an accepted one, or every error
// of a refused project as `file:line:col: message`, as `syncplc check` and
// a local `reload` print them.
#pragma once

#include <string>

#include "runtime/cli/api_client.hpp"

namespace syncplc::cli {

// Prints the answer and returns the exit status: 0 accepted, `rejected`
// for a project with errors (the running program goes on unchanged).
// Other refusals (401, 403, 409, ...) throw ApiError. `what` names the
// project in the error summary ("line.yaml").
int print_change_answer(const ApiClient& api, const ApiAnswer& a, const std::string& what, bool check_only,
                        int rejected);

}  // namespace syncplc::cli
