// Where an online command's password comes from, in this order: the
// environment (SYNCPLC_PASSWORD, for scripts and services), the first line
// of stdin (--password-stdin, for a secret piped from a vault), or a prompt
// on the terminal without echo. Never from the command line, where `ps`
// and the shell's history would show it.
#pragma once

#include <string>

namespace syncplc::cli {

// Throws std::runtime_error when there is none (no variable, no terminal).
std::string read_password(const std::string& user, bool from_stdin);

}  // namespace syncplc::cli
