#include "runtime/web/http_server.hpp"

#include <sys/socket.h>

#include <array>
#include <boost/asio/dispatch.hpp>
#include <boost/asio/executor_work_guard.hpp>
#include <boost/asio/io_context.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/post.hpp>
#include <boost/asio/ssl.hpp>
#include <boost/asio/steady_timer.hpp>
#include <boost/asio/strand.hpp>
#include <boost/asio/write.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/ssl.hpp>
#include <chrono>
#include <thread>
#include <future>
#include <map>
#include <mutex>
#include <optional>
#include <type_traits>
#include <vector>

#include "runtime/web/worker_pool.hpp"

namespace syncplc::web::http {
namespace net = boost::asio;
namespace beast = boost::beast;
namespace bhttp = boost::beast::http;
using tcp = net::ip::tcp;

namespace {

// A connection's read buffer: a header block (at most Limits::max_header_bytes)
// or a chunk line must fit; bodies pass through it in pieces.
constexpr std::size_t kReadBufferBytes = 64 * 1024;
// After refusing a request whose body is still coming, the connection reads
// (and drops) a little more before it closes, so the client reads the answer
// instead of a reset (a "lingering close"): at most this much, this long.
constexpr std::size_t kDrainBytes = 16 << 20;
constexpr std::size_t kDrainBufferBytes = 16 * 1024;
constexpr auto kDrainTime = std::chrono::seconds(1);
constexpr auto kTlsShutdownTime = std::chrono::seconds(1);
// accept() without a descriptor left (EMFILE): try again after a pause, not in a spin.
constexpr auto kAcceptPause = std::chrono::milliseconds(50);
// How long stop() lets the network threads run what it posted (the
// acceptor's close, every connection's close) before it stops them: those
// handlers take microseconds; the bound only keeps a stuck handler from
// holding stop() up.
constexpr auto kStopDrain = std::chrono::seconds(2);
// HMI pages that all reconnect at once (after a restart) are queued, not dropped.
constexpr int kListenBacklog = 128;

constexpr char kBusy[] =
    "HTTP/1.1 503 Service Unavailable\r\nContent-Type: application/json\r\nContent-Length: 76\r\n"
    "Connection: close\r\nRetry-After: 1\r\n\r\n"
    "{\"error\":\"this PLC serves as many HTTP connections as it may; try again later\"}";

std::chrono::milliseconds millis(std::int64_t v) { return std::chrono::milliseconds(v); }

}  // namespace

struct ConnectionBase {
  virtual ~ConnectionBase() = default;
  // Closes the socket (from any thread): what is pending ends with an error.
  virtual void cancel() = 0;
};

struct HttpServer::Impl {
  Impl(ServerOptions o, RequestHandler h, RefusalHandler r)
      : options(std::move(o)), handle(std::move(h)), refuse(std::move(r)) {}
  ServerOptions options;
  RequestHandler handle;
  RefusalHandler refuse;
  std::atomic<bool> stopping{false};
  std::atomic<std::size_t> open{0};
  std::atomic<std::size_t> refused{0};
  std::mutex registry_mutex;
  std::map<ConnectionBase*, std::weak_ptr<ConnectionBase>> registry;
  std::optional<net::ssl::context> tls;
  std::unique_ptr<WorkerPool> workers;
  std::unique_ptr<WorkerPool> network;
  int port = 0;
  // Destroyed before the members above (the connections its pending
  // handlers still hold use them); the acceptor and timer before it.
  net::io_context ioc;
  std::optional<net::executor_work_guard<net::io_context::executor_type>> work;
  std::optional<tcp::acceptor> acceptor;
  std::optional<net::steady_timer> accept_pause;

  void accept();
  void on_accept(const beast::error_code& ec, tcp::socket socket);
};

namespace {

template <class Stream>
class Connection final : public ConnectionBase, public std::enable_shared_from_this<Connection<Stream>> {
 public:
  static constexpr bool kTls = !std::is_same_v<Stream, beast::tcp_stream>;

  Connection(HttpServer::Impl& s, tcp::socket socket)
      : s_(s), stream_(make_stream(std::move(socket), s)), buffer_(kReadBufferBytes) {}

  ~Connection() override {
    {
      std::lock_guard lock(s_.registry_mutex);
      s_.registry.erase(this);
    }
    s_.open.fetch_sub(1);
  }

  void start() {
    {
      std::lock_guard lock(s_.registry_mutex);
      s_.registry[this] = this->weak_from_this();
    }
    net::dispatch(stream_.get_executor(), [self = this->shared_from_this()] { self->begin(); });
  }

  void cancel() override {
    net::post(stream_.get_executor(), [self = this->shared_from_this()] { self->lowest().close(); });
  }

 private:
  static Stream make_stream(tcp::socket&& socket, HttpServer::Impl& s) {
    if constexpr (kTls) return Stream(std::move(socket), *s.tls);
    else return Stream(std::move(socket));
  }

  auto& lowest() { return beast::get_lowest_layer(stream_); }
  const Limits& limits() const { return s_.options.limits; }

  void begin() {
    beast::error_code ec;
    const auto peer = lowest().socket().remote_endpoint(ec);
    if (!ec) {
      addr_ = peer.address().to_string();
      port_ = peer.port();
    }
    lowest().socket().set_option(tcp::no_delay(true), ec);
    if constexpr (kTls) {
      // The handshake counts against the header deadline: a client that
      // opens a TLS connection and says nothing is cut as a slow one is.
      lowest().expires_after(millis(limits().header_timeout_ms));
      stream_.async_handshake(net::ssl::stream_base::server, [self = this->shared_from_this()](beast::error_code e) {
        if (e) self->lowest().close();
        else self->read_head();
      });
    } else {
      read_head();
    }
  }

  // One deadline for the whole header block, from the last answer on: an
  // idle keep-alive connection and a client sending its head byte by byte
  // (slowloris) are both cut by it.
  void read_head() {
    if (s_.stopping) {
      lowest().close();
      return;
    }
    parser_.emplace();
    parser_->header_limit(static_cast<std::uint32_t>(limits().max_header_bytes));
    parser_->body_limit(limits().max_upload_body);
    lowest().expires_after(millis(limits().header_timeout_ms));
    bhttp::async_read_header(stream_, buffer_, *parser_, [self = this->shared_from_this()](beast::error_code ec, std::size_t) {
      self->on_head(ec);
    });
  }

  void on_head(const beast::error_code& ec) {
    if (ec) {
      fail(ec);
      return;
    }
    version_ = parser_->get().version();
    std::size_t body_limit = 0;
    if (Refusal r = check_head(parser_->get().base(), limits(), &body_limit)) {
      refuse(r);
      return;
    }
    parser_->body_limit(body_limit);
    head_fields_ = field_count(parser_->get().base());
    if (!parser_->is_done() && beast::iequals(parser_->get()[bhttp::field::expect], "100-continue")) {
      auto go_on = std::make_shared<bhttp::response<bhttp::empty_body>>(bhttp::status::continue_, version_);
      lowest().expires_after(millis(limits().write_timeout_ms));
      bhttp::async_write(stream_, *go_on, [self = this->shared_from_this(), go_on](beast::error_code e, std::size_t) {
        if (e) self->lowest().close();
        else self->read_body();
      });
      return;
    }
    read_body();
  }

  void read_body() {
    if (parser_->is_done()) {
      on_body({});
      return;
    }
    lowest().expires_after(millis(limits().body_timeout_ms));
    bhttp::async_read(stream_, buffer_, *parser_, [self = this->shared_from_this()](beast::error_code ec, std::size_t) {
      self->on_body(ec);
    });
  }

  void on_body(const beast::error_code& ec) {
    if (ec) {
      fail(ec);
      return;
    }
    lowest().expires_never();
    auto req = std::make_shared<Request>();
    auto& msg = parser_->get();
    if (Refusal r = to_request(msg.base(), std::move(msg.body()), head_fields_, req.get())) {
      refuse(r);
      return;
    }
    req->remote_addr = addr_;
    req->remote_port = port_;
    head_only_ = msg.method() == bhttp::verb::head;
    keep_alive_ = msg.keep_alive() && ++served_ < limits().max_requests_per_connection;
    parser_.reset();
    if (s_.stopping) {
      lowest().close();
      return;
    }
    s_.workers->enqueue([self = this->shared_from_this(), req] { self->serve(*req); });
  }

  // A read that failed: a refusal answered, or (the client left, a
  // deadline passed) the connection closed.
  void fail(const beast::error_code& ec) {
    const auto data = buffer_.data();
    const Refusal r = refusal_for(ec, std::string_view(static_cast<const char*>(data.data()), data.size()));
    if (r) refuse(r);
    else lowest().close();
  }

  template <class Body>
  void fill(bhttp::response<Body>& m, const Response& res) {
    m.result(static_cast<unsigned>(res.status));
    m.version(version_);
    for (const auto& [name, value] : res.headers) m.insert(name, value);
    m.keep_alive(keep_alive_);
  }

  // On a network thread: the refusal's answer, then a lingering close.
  void refuse(const Refusal& r) {
    Response res;
    s_.refuse(r, res);
    keep_alive_ = false;
    if (version_ != 10) version_ = 11;
    auto msg = std::make_shared<bhttp::response<bhttp::string_body>>();
    fill(*msg, res);
    msg->body() = std::move(res.body);
    msg->prepare_payload();
    lowest().expires_after(millis(limits().write_timeout_ms));
    bhttp::async_write(stream_, *msg, [self = this->shared_from_this(), msg](beast::error_code ec, std::size_t) {
      if (ec) self->lowest().close();
      else self->linger();
    });
  }

  void linger() {
    if constexpr (kTls) {
      finish();
    } else {
      beast::error_code ec;
      lowest().socket().shutdown(tcp::socket::shutdown_send, ec);
      drain_ = std::make_unique<std::array<char, kDrainBufferBytes>>();
      lowest().expires_after(kDrainTime);
      drain();
    }
  }

  void drain() {
    lowest().async_read_some(net::buffer(*drain_), [self = this->shared_from_this()](beast::error_code ec, std::size_t n) {
      self->drained_ += n;
      if (ec || self->drained_ > kDrainBytes) self->lowest().close();
      else self->drain();
    });
  }

  // The end of a connection that answered all it read.
  void finish() {
    if constexpr (kTls) {
      lowest().expires_after(kTlsShutdownTime);
      stream_.async_shutdown([self = this->shared_from_this()](beast::error_code) { self->lowest().close(); });
    } else {
      beast::error_code ec;
      lowest().socket().shutdown(tcp::socket::shutdown_both, ec);
      lowest().close();
    }
  }

  // From a worker: runs `start(handler)` on the connection's strand under the
  // write timeout and waits for its end. False when the write failed.
  template <class Start>
  bool blocking(Start start) {
    auto done = std::make_shared<std::promise<beast::error_code>>();
    auto result = done->get_future();
    net::post(stream_.get_executor(), [this, self = this->shared_from_this(), done, &start] {
      lowest().expires_after(millis(limits().write_timeout_ms));
      start([this, self, done](beast::error_code ec, std::size_t) {
        lowest().expires_never();
        done->set_value(ec);
      });
    });
    try {
      return !result.get();
    } catch (const std::future_error&) {
      return false;  // the server stopped before the write ran
    }
  }

  class Sink final : public DataSink {
   public:
    Sink(Connection& c, bool chunked) : c_(c), chunked_(chunked) {}
    bool write(const char* data, std::size_t size) override {
      if (!ok || finished) return false;
      if (chunked_) {
        const auto chunk = bhttp::make_chunk(net::const_buffer(data, size));
        ok = c_.blocking([&](auto h) { net::async_write(c_.stream_, chunk, std::move(h)); });
      } else {
        ok = c_.blocking([&](auto h) { net::async_write(c_.stream_, net::const_buffer(data, size), std::move(h)); });
      }
      sent += size;
      return ok;
    }
    void done() override { finished = true; }
    bool is_writable() const override { return ok && !c_.s_.stopping; }
    bool ok = true;
    bool finished = false;
    std::size_t sent = 0;

   private:
    Connection& c_;
    bool chunked_;
  };

  // On a worker: the handler, then its answer.
  void serve(Request& req) {
    Response res;
    bool ok = false;
    try {
      s_.handle(req, res);
      ok = res.provider ? stream(res) : answer(res);
    } catch (const std::exception&) {
      ok = false;  // an answer Beast cannot send (a header value with a line break): the connection ends
    }
    if (ok && keep_alive_ && !s_.stopping)
      net::post(stream_.get_executor(), [self = this->shared_from_this()] { self->read_head(); });
    else
      net::post(stream_.get_executor(), [self = this->shared_from_this()] { self->finish(); });
  }

  bool answer(Response& res) {
    if (head_only_) {
      bhttp::response<bhttp::empty_body> msg;
      fill(msg, res);
      msg.content_length(res.body.size());
      return blocking([&](auto h) { bhttp::async_write(stream_, msg, std::move(h)); });
    }
    bhttp::response<bhttp::string_body> msg;
    fill(msg, res);
    msg.body() = std::move(res.body);
    msg.prepare_payload();
    return blocking([&](auto h) { bhttp::async_write(stream_, msg, std::move(h)); });
  }

  // A stream (Server-Sent Events): chunked on HTTP/1.1, until the provider
  // ends it or a write fails; the connection closes after it.
  bool stream(Response& res) {
    keep_alive_ = false;
    bhttp::response<bhttp::empty_body> msg;
    fill(msg, res);
    const bool chunked = version_ >= 11;
    if (chunked) msg.chunked(true);
    bhttp::response_serializer<bhttp::empty_body> header(msg);
    Sink sink(*this, chunked);
    sink.ok = blocking([&](auto h) { bhttp::async_write_header(stream_, header, std::move(h)); });
    while (sink.ok && !sink.finished && !s_.stopping)
      if (!res.provider(sink.sent, sink)) sink.ok = false;
    if (sink.ok && sink.finished && chunked) {
      const auto last = bhttp::make_chunk_last();
      sink.ok = blocking([&](auto h) { net::async_write(stream_, last, std::move(h)); });
    }
    if (res.releaser) res.releaser(sink.ok && sink.finished);
    return sink.ok && sink.finished;
  }

  HttpServer::Impl& s_;
  Stream stream_;
  beast::flat_buffer buffer_;
  std::optional<bhttp::request_parser<bhttp::string_body>> parser_;
  std::size_t served_ = 0;
  std::size_t head_fields_ = 0;
  unsigned version_ = 11;
  bool keep_alive_ = false;
  bool head_only_ = false;
  std::string addr_;
  int port_ = 0;
  std::unique_ptr<std::array<char, kDrainBufferBytes>> drain_;
  std::size_t drained_ = 0;
};

}  // namespace

void HttpServer::Impl::accept() {
  acceptor->async_accept(net::make_strand(ioc), [this](beast::error_code ec, tcp::socket socket) {
    on_accept(ec, std::move(socket));
  });
}

void HttpServer::Impl::on_accept(const beast::error_code& ec, tcp::socket socket) {
  if (stopping || !acceptor->is_open()) return;
  if (ec) {
    if (ec == net::error::operation_aborted) return;
    // No descriptor left (EMFILE, ENFILE) or a connection reset before it
    // was taken: accept again in a moment.
    accept_pause->expires_after(kAcceptPause);
    accept_pause->async_wait([this](beast::error_code e) {
      if (!e && !stopping) accept();
    });
    return;
  }
  if (open.load() >= options.max_connections) {
    // Refused at once, never queued: the connection's descriptor is given
    // back now. Plain HTTP gets a 503 if its socket takes it without waiting.
    refused.fetch_add(1, std::memory_order_relaxed);
    if (!tls) ::send(socket.native_handle(), kBusy, sizeof kBusy - 1, MSG_DONTWAIT | MSG_NOSIGNAL);
    beast::error_code ignored;
    socket.shutdown(tcp::socket::shutdown_both, ignored);
    socket.close(ignored);
  } else {
    open.fetch_add(1);
    if (tls) std::make_shared<Connection<beast::ssl_stream<beast::tcp_stream>>>(*this, std::move(socket))->start();
    else std::make_shared<Connection<beast::tcp_stream>>(*this, std::move(socket))->start();
  }
  accept();
}

HttpServer::HttpServer(ServerOptions options, RequestHandler handle, RefusalHandler refuse)
    : impl_(std::make_unique<Impl>(std::move(options), std::move(handle), std::move(refuse))) {}

HttpServer::~HttpServer() { stop(); }

bool HttpServer::start(std::string* error) {
  Impl& s = *impl_;
  const ServerOptions& o = s.options;
  beast::error_code ec;
  if (!o.tls_cert.empty()) {
    s.tls.emplace(net::ssl::context::tls_server);
    s.tls->set_options(net::ssl::context::default_workarounds | net::ssl::context::no_sslv2 |
                       net::ssl::context::no_sslv3 | net::ssl::context::no_tlsv1 | net::ssl::context::no_tlsv1_1 |
                       net::ssl::context::single_dh_use);
    s.tls->use_certificate_chain_file(o.tls_cert, ec);
    if (!ec) s.tls->use_private_key_file(o.tls_key, net::ssl::context::pem, ec);
    if (ec) {
      *error = "HTTPS: cannot load the certificate " + o.tls_cert + " with the key " + o.tls_key + " (" + ec.message() + ")";
      s.tls.reset();
      return false;
    }
  }
  const auto address = net::ip::make_address(o.bind, ec);
  if (ec) {
    *error = "'" + o.bind + "' is not an IP address";
    return false;
  }
  const tcp::endpoint endpoint(address, static_cast<unsigned short>(o.port));
  s.acceptor.emplace(net::make_strand(s.ioc));
  s.acceptor->open(endpoint.protocol(), ec);
  if (!ec) s.acceptor->set_option(net::socket_base::reuse_address(true), ec);
  if (!ec) s.acceptor->bind(endpoint, ec);
  if (!ec) s.acceptor->listen(kListenBacklog, ec);
  if (ec) {
    *error = ec.message();
    s.acceptor.reset();
    return false;
  }
  s.port = s.acceptor->local_endpoint(ec).port();
  s.accept_pause.emplace(s.acceptor->get_executor());
  s.work.emplace(s.ioc.get_executor());
  s.workers = std::make_unique<WorkerPool>(o.workers, "http-work");
  s.network = std::make_unique<WorkerPool>(o.network_threads, "http-net");
  for (std::size_t i = 0; i < o.network_threads; ++i)
    s.network->enqueue([&s] {
      for (;;) {
        try {
          s.ioc.run();
          return;
        } catch (const std::exception&) {
          // One connection's failure (an answer that cannot be serialized)
          // ends that handler only; the thread serves on.
        }
      }
    });
  net::post(s.acceptor->get_executor(), [&s] { s.accept(); });
  return true;
}

void HttpServer::stop() {
  Impl& s = *impl_;
  if (!s.network) return;
  s.stopping = true;
  net::post(s.acceptor->get_executor(), [&s] {
    beast::error_code ec;
    s.acceptor->close(ec);
    s.accept_pause->cancel();
  });
  std::vector<std::shared_ptr<ConnectionBase>> open;
  {
    std::lock_guard lock(s.registry_mutex);
    for (auto& [p, weak] : s.registry)
      if (auto c = weak.lock()) open.push_back(std::move(c));
  }
  for (auto& c : open) c->cancel();
  open.clear();  // outside the lock: a connection's destructor takes it
  // Workers first: what they hold writes through the network threads.
  s.workers->shutdown();
  s.work.reset();
  // The closes above are posted, not done: stopping the io_context at once
  // would leave them queued, and a connection the acceptor had just taken
  // (or one only posted a close) open until the server is destroyed. With
  // the work guard gone, the io_context runs dry once every socket is closed
  // and every handler has seen `stopping`.
  const auto drain_until = std::chrono::steady_clock::now() + kStopDrain;
  while (!s.ioc.stopped() && std::chrono::steady_clock::now() < drain_until)
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  s.ioc.stop();
  s.network->shutdown();
  // What a network thread queued after the workers ended is dropped here,
  // while the io_context its sockets belong to still exists.
  s.workers.reset();
  s.network.reset();
}

std::string HttpServer::keep_to(const cpu_set_t& cpus) {
  Impl& s = *impl_;
  if (!s.network) return {};
  std::string why = s.network->keep_to(cpus);
  if (why.empty()) why = s.workers->keep_to(cpus);
  return why;
}

int HttpServer::port() const { return impl_->port; }

std::size_t HttpServer::connections() const { return impl_->open.load(); }

std::size_t HttpServer::refused_connections() const { return impl_->refused.load(); }

}  // namespace syncplc::web::http
