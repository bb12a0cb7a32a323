// The API's routes: a method and a path pattern (a regex, matched against
// the whole decoded path; its groups become Request::matches) to a handler.
#pragma once

#include <functional>
#include <regex>
#include <string>
#include <vector>

#include "runtime/web/http/message.hpp"

namespace syncplc::web::http {

using Handler = std::function<void(const Request&, Response&)>;

class Router {
 public:
  void Get(const std::string& pattern, Handler h) { add("GET", pattern, std::move(h)); }
  void Post(const std::string& pattern, Handler h) { add("POST", pattern, std::move(h)); }
  void Put(const std::string& pattern, Handler h) { add("PUT", pattern, std::move(h)); }
  void Patch(const std::string& pattern, Handler h) { add("PATCH", pattern, std::move(h)); }
  void Delete(const std::string& pattern, Handler h) { add("DELETE", pattern, std::move(h)); }
  void add(std::string method, const std::string& pattern, Handler h);

  enum class Outcome { Handled, NoRoute };
  // Runs the first route whose method and pattern match (HEAD as GET),
  // with req.matches filled.
  Outcome dispatch(Request& req, Response& res) const;

 private:
  struct Route {
    std::string method;
    std::regex pattern;
    Handler handler;
  };
  std::vector<Route> routes_;
};

}  // namespace syncplc::web::http
