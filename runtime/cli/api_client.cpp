#include "runtime/cli/api_client.hpp"

#include <httplib.h>

#include <cctype>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <regex>

#include "runtime/cli/commands.hpp"
#include "runtime/cli/password_input.hpp"

namespace syncplc::cli {
namespace {

// Answers come within a request; a PLC that accepted the connection but
// says nothing for this long is as good as gone.
constexpr int kConnectTimeoutS = 5;
constexpr int kReadTimeoutS = 30;
// A load, reload or rollback is answered once every task has switched:
// three periods of the slowest task ahead (half a minute for a 10 s task),
// plus the store's record of the version.
constexpr int kChangeTimeoutS = 300;
// The live stream sends at least once a second (rate >= 1): a silence this
// long means the connection is dead even if TCP has not noticed.
constexpr int kStreamSilenceS = 10;

std::string env(const char* name) {
  const char* v = std::getenv(name);
  return v ? v : "";
}

std::string status_words(int status) {
  switch (status) {
    case 400: return "rejected (400)";
    case 401: return "not logged in (401)";
    // The PLC's reason follows: a role too low, a tag without hmi: readwrite or hmi: none.
    case 403: return "forbidden (403)";
    case 404: return "not found (404)";
    case 405: return "method not allowed (405)";
    // The PLC's reason follows: the program writes the tag, a stopped task, a change under way.
    case 409: return "refused (409)";
    case 413: return "too large (413)";
    case 415: return "not JSON (415)";
    case 429: return "too many login attempts (429)";
    case 503: return "busy (503)";
    default: return "refused (" + std::to_string(status) + ")";
  }
}

}  // namespace

std::optional<ApiUrl> parse_api_url(const std::string& url, std::string* error) {
  // scheme://host[:port][/prefix]; an IPv6 host in brackets.
  static const std::regex re(R"(^(https?)://(\[[0-9A-Fa-f:.]+\]|[^:/?#\[\]]+)(?::(\d{1,5}))?(/[^?#]*)?$)");
  std::smatch m;
  if (!std::regex_match(url, m, re)) {
    *error = "--url " + url + ": expected http://HOST[:PORT] or https://HOST[:PORT], e.g. " + kDefaultApiUrl;
    return std::nullopt;
  }
  ApiUrl u;
  u.scheme = m[1];
  u.host = m[2];
  u.port = m[3].matched ? std::stoi(m[3]) : (u.scheme == "https" ? 443 : 80);
  if (u.port < 1 || u.port > 65535) {
    *error = "--url " + url + ": port " + std::string(m[3]) + " is not 1..65535";
    return std::nullopt;
  }
  u.base_path = m[4].matched ? std::string(m[4]) : "";
  while (!u.base_path.empty() && u.base_path.back() == '/') u.base_path.pop_back();
  u.text = url;
  return u;
}

std::string effective_url(const std::string& flag) {
  if (!flag.empty()) return flag;
  const std::string e = env("SYNCPLC_URL");
  return e.empty() ? kDefaultApiUrl : e;
}

bool api_url_given(const std::string& flag) { return !flag.empty() || !env("SYNCPLC_URL").empty(); }

std::string refusal_words(int status, const nlohmann::json& body) {
  std::string words = status_words(status);
  if (body.is_object() && body.contains("error") && body["error"].is_string()) {
    words += ": ";
    if (body.contains("where") && body["where"].is_string()) words += body["where"].get<std::string>() + ": ";
    words += body["error"].get<std::string>();
  }
  return words;
}

std::string url_encode(std::string_view s) {
  static const char* hex = "0123456789ABCDEF";
  std::string out;
  for (unsigned char c : s) {
    if (std::isalnum(c) || c == '-' || c == '_' || c == '.' || c == '~') {
      out += static_cast<char>(c);
    } else {
      out += '%';
      out += hex[c >> 4];
      out += hex[c & 15];
    }
  }
  return out;
}

ApiClient::ApiClient(const ApiUrl& url, const std::string& cacert) : url_(url) {
  http_ = std::make_unique<httplib::Client>(url.scheme + "://" + url.host + ":" + std::to_string(url.port));
  if (!http_->is_valid()) throw ApiError(kExitInvalid, "--url " + url.text + ": this build cannot speak " + url.scheme);
  http_->set_connection_timeout(kConnectTimeoutS);
  http_->set_read_timeout(kReadTimeoutS);
  http_->set_keep_alive(true);  // login, requests and logout on one connection
  if (url.scheme == "https") {
    if (!cacert.empty()) {
      if (!std::filesystem::exists(cacert)) throw ApiError(kExitInvalid, "--cacert " + cacert + ": no such file");
      http_->set_ca_cert_path(cacert);
    }
    http_->enable_server_certificate_verification(true);
  } else if (!cacert.empty()) {
    throw ApiError(kExitInvalid, "--cacert is for an https URL; " + url.text + " is plain http");
  }
}

ApiClient::~ApiClient() { logout(); }

void ApiClient::unreachable(int error_code) const {
  const auto e = static_cast<httplib::Error>(error_code);
  std::string words;
  switch (e) {
    case httplib::Error::Connection:
    case httplib::Error::ConnectionTimeout:
      words = "no syncplc run answers at " + url_.text + " (is it running with its HTTP server on?)";
      break;
    case httplib::Error::SSLConnection:
      words = url_.text + ": the TLS connection failed (is it an https server?)";
      break;
    case httplib::Error::SSLLoadingCerts:
      words = "--cacert: cannot load the certificate file";
      break;
    case httplib::Error::SSLServerVerification:
      words = url_.text + ": the server's certificate is not trusted (give its certificate with --cacert FILE)";
      break;
    case httplib::Error::Read:
      words = url_.text + " stopped answering (connection closed or no answer within " +
              std::to_string(kReadTimeoutS) + " s)";
      break;
    default:
      words = url_.text + ": " + httplib::to_string(e);
  }
  throw ApiError(kExitUnreachable, words);
}

ApiAnswer ApiClient::request(const std::string& method, const std::string& path, const nlohmann::json* body) {
  httplib::Request req;
  req.method = method;
  req.path = api_path(path);
  if (!token_.empty()) req.headers.emplace("Authorization", "Bearer " + token_);
  if (body) {
    req.body = body->dump();
    req.headers.emplace("Content-Type", "application/json");
  } else if (method == "POST" || method == "PUT") {
    req.body = "{}";  // the API wants JSON on every POST (415 otherwise)
    req.headers.emplace("Content-Type", "application/json");
  }
  const bool change = path.rfind("/projects/", 0) == 0;
  if (change) http_->set_read_timeout(kChangeTimeoutS);
  auto res = http_->send(req);
  if (change) http_->set_read_timeout(kReadTimeoutS);
  if (!res) unreachable(static_cast<int>(res.error()));
  ApiAnswer a;
  a.status = res->status;
  a.body = res->body;
  a.json = nlohmann::json::parse(a.body, nullptr, /*allow_exceptions=*/false);
  if (a.json.is_discarded()) a.json = nullptr;
  if (a.status == 429 && res->has_header("Retry-After") && a.json.is_object() && a.json.contains("error") &&
      a.json["error"].is_string())
    a.json["error"] = a.json["error"].get<std::string>() + "; try again in " + res->get_header_value("Retry-After") + " s";
  return a;
}

ApiAnswer ApiClient::call(const std::string& method, const std::string& path, const nlohmann::json* body) {
  ApiAnswer a = request(method, path, body);
  if (a.status < 200 || a.status > 299) refuse(a);
  return a;
}

void ApiClient::refuse(const ApiAnswer& a) const {
  std::string words = refusal_words(a.status, a.json);
  if (a.status == 401) words += logged_in() ? " (the login has ended: run the command again)" : " (log in with --user NAME)";
  throw ApiError(kExitInvalid, words);
}

void ApiClient::login(const std::string& user, const std::string& password) {
  const nlohmann::json body = {{"user", user}, {"password", password}};
  ApiAnswer a = request("POST", "/login", &body);
  if (a.status != 200 || !a.json.is_object() || !a.json.contains("token") || !a.json["token"].is_string()) {
    // A 401 here is the password or the name, not a missing login.
    std::string words = refusal_words(a.status, a.json);
    if (a.status == 401) words.replace(0, words.find(')') + 1, "refused (401)");
    throw ApiError(kExitInvalid, "login as " + user + ": " + words);
  }
  token_ = a.json["token"].get<std::string>();
}

void ApiClient::logout() {
  if (token_.empty()) return;
  httplib::Headers h = {{"Authorization", "Bearer " + token_}};
  token_.clear();
  http_->Post(api_path("/logout"), h, std::string("{}"), std::string("application/json"));  // the token also ends by itself
}

bool ApiClient::stream(const std::string& path, const std::function<bool(std::string_view)>& on_chunk) {
  httplib::Headers h = {{"Accept", "text/event-stream"}};
  if (!token_.empty()) h.emplace("Authorization", "Bearer " + token_);
  http_->set_read_timeout(kStreamSilenceS);
  int status = 0;
  std::string refused;  // the body of an answer other than 200
  auto res = http_->Get(
      api_path(path).c_str(), h,
      [&](const httplib::Response& r) {
        status = r.status;
        return true;
      },
      [&](const char* data, std::size_t n) {
        if (status != 200) {
          refused.append(data, n);
          return true;
        }
        return on_chunk(std::string_view(data, n));
      });
  http_->set_read_timeout(kReadTimeoutS);
  if (stopping_) return false;
  if (!res) {
    if (res.error() == httplib::Error::Canceled) return true;  // on_chunk had enough
    if (res.error() == httplib::Error::Read && status == 200)
      throw ApiError(kExitUnreachable, "the live stream from " + url_.text + " stopped (nothing for " +
                                           std::to_string(kStreamSilenceS) + " s, or the connection closed)");
    unreachable(static_cast<int>(res.error()));
  }
  if (res->status != 200) {
    auto j = nlohmann::json::parse(refused.empty() ? res->body : refused, nullptr, false);
    throw ApiError(kExitInvalid, refusal_words(res->status, j.is_discarded() ? nlohmann::json() : j));
  }
  return true;
}

void ApiClient::stop() {
  stopping_ = true;
  http_->stop();  // shuts the socket down only: safe while another thread reads it
}

std::unique_ptr<ApiClient> connect_api(const OnlineOptions& o) {
  const std::string text = effective_url(o.url);
  std::string err;
  auto url = parse_api_url(text, &err);
  if (!url) throw ApiError(kExitInvalid, err);
  auto client = std::make_unique<ApiClient>(*url, o.cacert);
  const std::string user = o.user.empty() ? env("SYNCPLC_USER") : o.user;
  if (!user.empty()) client->login(user, read_password(user, o.password_stdin));
  return client;
}

int run_online(const char* command, const std::function<int()>& body) {
  try {
    return body();
  } catch (const ApiError& e) {
    std::cout.flush();
    std::cerr << "syncplc: " << command << ": " << e.what() << "\n";
    return e.exit_status();
  } catch (const nlohmann::json::exception& e) {
    // An answer of another shape than docs/http-api.md says.
    std::cout.flush();
    std::cerr << "syncplc: " << command << ": unexpected answer from the PLC: " << e.what() << "\n";
    return kExitInvalid;
  } catch (const std::exception& e) {
    std::cout.flush();
    std::cerr << "syncplc: " << command << ": " << e.what() << "\n";
    return kExitInvalid;
  }
}

}  // namespace syncplc::cli
