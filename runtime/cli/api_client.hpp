// The online commands' side of the HTTP API (docs/http-api.md): where the
// PLC is, logging in and out, one request with a JSON body, and every
// refusal or transport failure in words with the exit status it means.
#pragma once

#include <atomic>
#include <functional>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>

namespace httplib {
class Client;
}

namespace syncplc::cli {

// `syncplc run`'s API when neither --url nor SYNCPLC_URL names another.
inline constexpr const char* kDefaultApiUrl = "http://127.0.0.1:8080";

// The options every online command takes (docs/user-guide.md, "Online commands").
struct OnlineOptions {
  std::string url;              // --url; "" : $SYNCPLC_URL, else kDefaultApiUrl
  std::string cacert;           // --cacert: the CA (or self-signed) certificate of an https URL
  std::string user;             // --user; "" : $SYNCPLC_USER, else anonymous
  bool password_stdin = false;  // the password is the first line of stdin
  bool json = false;            // --json: the server's answer as it came
};

// An http or https URL split: the client connects to scheme://host:port and
// puts base_path (a reverse proxy's prefix, "" usually) before /api/v1.
struct ApiUrl {
  std::string scheme, host;
  int port = 0;
  std::string base_path;
  std::string text;  // as given, for messages
};
std::optional<ApiUrl> parse_api_url(const std::string& url, std::string* error);
// --url if given, else $SYNCPLC_URL, else kDefaultApiUrl.
std::string effective_url(const std::string& flag);
// Whether events and reload should go through the API: --url or $SYNCPLC_URL.
bool api_url_given(const std::string& flag);

// A refusal or failure, in words, with the exit status it ends the command with.
class ApiError : public std::runtime_error {
 public:
  ApiError(int exit_status, const std::string& what) : std::runtime_error(what), exit_status_(exit_status) {}
  int exit_status() const { return exit_status_; }

 private:
  int exit_status_;
};

struct ApiAnswer {
  int status = 0;
  std::string body;     // as it came (--json prints it)
  nlohmann::json json;  // parsed; null when the body is not JSON
};

// "not logged in (401): log in first ..." — the status in words and the
// server's own {"error"} text (and "where", for a project).
std::string refusal_words(int status, const nlohmann::json& body);
// Percent-encodes everything but unreserved characters, for a ref in a path
// or a query ("pos[2]" -> "pos%5B2%5D").
std::string url_encode(std::string_view s);

class ApiClient {
 public:
  ApiClient(const ApiUrl& url, const std::string& cacert);
  ~ApiClient();  // logs out
  ApiClient(const ApiClient&) = delete;
  ApiClient& operator=(const ApiClient&) = delete;

  // POST /login; the token then goes with every request. Throws ApiError.
  void login(const std::string& user, const std::string& password);
  // POST /logout, once; quiet about failures (the token ends by itself).
  void logout();
  bool logged_in() const { return !token_.empty(); }
  const std::string& url() const { return url_.text; }

  // One request under /api/v1 (path "/status"); a JSON body for POST and PUT.
  // Throws ApiError when the PLC cannot be reached; any HTTP status returns.
  ApiAnswer request(const std::string& method, const std::string& path, const nlohmann::json* body = nullptr);
  // The same, and a status other than 2xx throws ApiError with its words.
  ApiAnswer call(const std::string& method, const std::string& path, const nlohmann::json* body = nullptr);
  nlohmann::json get(const std::string& path) { return call("GET", path).json; }
  // Throws the ApiError an answer other than 2xx means (401 with a hint to log in).
  [[noreturn]] void refuse(const ApiAnswer& a) const;

  // GET a long answer (the live stream): `on_chunk` gets the body's bytes as
  // they come and returns false to end it. A status other than 200 throws
  // ApiError with its words; the end of the stream returns normally.
  // Returns false when stop() ended it.
  bool stream(const std::string& path, const std::function<bool(std::string_view)>& on_chunk);
  // Ends a stream() running on another thread (Ctrl-C).
  void stop();

 private:
  std::string api_path(const std::string& path) const { return url_.base_path + "/api/v1" + path; }
  [[noreturn]] void unreachable(int error_code) const;

  ApiUrl url_;
  std::unique_ptr<httplib::Client> http_;
  std::string token_;
  std::atomic<bool> stopping_{false};
};

// The client of one online command: the URL resolved, logged in when a user
// is given (--user or $SYNCPLC_USER; the password from $SYNCPLC_PASSWORD,
// --password-stdin or the terminal), logged out when it goes.
std::unique_ptr<ApiClient> connect_api(const OnlineOptions& o);

// Runs an online command's body: ApiError and other failures become
// "syncplc: COMMAND: words" on stderr and their exit status.
int run_online(const char* command, const std::function<int()>& body);

}  // namespace syncplc::cli
