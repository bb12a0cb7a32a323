#include "runtime/web/http/router.hpp"

namespace syncplc::web::http {

void Router::add(std::string method, const std::string& pattern, Handler h) {
  routes_.push_back({std::move(method), std::regex(pattern), std::move(h)});
}

Router::Outcome Router::dispatch(Request& req, Response& res) const {
  const std::string& method = req.method == "HEAD" ? std::string("GET") : req.method;
  for (const Route& r : routes_) {
    if (r.method != method) continue;
    std::smatch m;
    if (!std::regex_match(req.path, m, r.pattern)) continue;
    req.matches.clear();
    for (const auto& group : m) req.matches.push_back(group.str());
    r.handler(req, res);
    return Outcome::Handled;
  }
  return Outcome::NoRoute;
}

}  // namespace syncplc::web::http
