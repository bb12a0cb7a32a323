#include "runtime/cli/password_input.hpp"

#include <fcntl.h>
#include <termios.h>
#include <unistd.h>

#include <cstdlib>
#include <iostream>
#include <stdexcept>

namespace syncplc::cli {
namespace {

void strip_line_end(std::string& s) {
  while (!s.empty() && (s.back() == '\n' || s.back() == '\r')) s.pop_back();
}

// Asks on /dev/tty, so that a command whose output is piped still asks its
// user; echo is off while the password is typed.
std::string ask_terminal(const std::string& user) {
  const int fd = open("/dev/tty", O_RDWR | O_NOCTTY | O_CLOEXEC);
  if (fd < 0)
    throw std::runtime_error("a password for " + user +
                             " is needed: set SYNCPLC_PASSWORD or give --password-stdin (no terminal to ask on)");
  const std::string prompt = "password for " + user + ": ";
  (void)!write(fd, prompt.data(), prompt.size());
  termios old{};
  const bool is_tty = tcgetattr(fd, &old) == 0;
  if (is_tty) {
    termios quiet = old;
    quiet.c_lflag &= ~static_cast<tcflag_t>(ECHO);
    tcsetattr(fd, TCSAFLUSH, &quiet);
  }
  std::string line;
  char c = 0;
  while (read(fd, &c, 1) == 1 && c != '\n') line += c;
  if (is_tty) tcsetattr(fd, TCSAFLUSH, &old);
  (void)!write(fd, "\n", 1);
  close(fd);
  strip_line_end(line);
  return line;
}

}  // namespace

std::string read_password(const std::string& user, bool from_stdin) {
  if (const char* p = std::getenv("SYNCPLC_PASSWORD"); p && *p) return p;
  if (from_stdin) {
    std::string line;
    if (!std::getline(std::cin, line)) throw std::runtime_error("--password-stdin: stdin is empty");
    strip_line_end(line);
    return line;
  }
  return ask_terminal(user);
}

}  // namespace syncplc::cli
