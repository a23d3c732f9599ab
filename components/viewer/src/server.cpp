#include "skelgraph/viewer/server.hpp"

#include <filesystem>
#include <fstream>
#include <optional>
#include <set>
#include <sstream>
#include <stdexcept>
#include <thread>

#include <boost/asio.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/websocket.hpp>

#include "skelgraph/viewer/client_command.hpp"
#include "skelgraph/viewer/outbox.hpp"

namespace skelgraph::viewer {

namespace beast = boost::beast;
namespace http = beast::http;
namespace websocket = beast::websocket;
namespace net = boost::asio;
using tcp = net::ip::tcp;

namespace {

std::string content_type_of(const std::filesystem::path& p) {
  const auto ext = p.extension().string();
  if (ext == ".html") return "text/html; charset=utf-8";
  if (ext == ".js" || ext == ".mjs") return "text/javascript; charset=utf-8";
  if (ext == ".css") return "text/css; charset=utf-8";
  if (ext == ".json") return "application/json";
  if (ext == ".svg") return "image/svg+xml";
  if (ext == ".png") return "image/png";
  return "application/octet-stream";
}

constexpr std::uintmax_t kMaxAssetBytes = 64u << 20;

}  // namespace

std::map<std::string, Asset> load_assets(const std::string& dir) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (!fs::is_regular_file(fs::path(dir) / "index.html", ec))
    throw std::runtime_error("viewer: no page in " + dir +
                             " (index.html missing: the build's viewer_web target makes it; it needs npm)");
  std::map<std::string, Asset> out;
  std::uintmax_t total = 0;
  for (const auto& e : fs::recursive_directory_iterator(dir)) {
    if (!e.is_regular_file()) continue;
    total += e.file_size();
    if (total > kMaxAssetBytes) throw std::runtime_error("viewer: " + dir + " holds more than 64 MiB: not a page folder");
    std::ifstream in(e.path(), std::ios::binary);
    std::ostringstream body;
    body << in.rdbuf();
    out[fs::relative(e.path(), dir).generic_string()] = Asset{body.str(), content_type_of(e.path())};
  }
  return out;
}

class WsSession;

class Server::Impl {
 public:
  Impl(Options o, OnMessage on_message)
      : options_(std::move(o)), on_message_(std::move(on_message)), acceptor_(ioc_) {
    beast::error_code ec;
    const auto address = net::ip::make_address(options_.address, ec);
    if (ec) throw std::runtime_error("viewer: '" + options_.address + "' is not an IP address");
    const tcp::endpoint ep(address, options_.port);
    acceptor_.open(ep.protocol(), ec);
    if (!ec) acceptor_.set_option(net::socket_base::reuse_address(true), ec);
    if (!ec) acceptor_.bind(ep, ec);
    if (!ec) acceptor_.listen(net::socket_base::max_listen_connections, ec);
    if (ec)
      throw std::runtime_error("viewer: cannot listen on " + options_.address + ":" + std::to_string(options_.port) +
                               ": " + ec.message());
    port_ = acceptor_.local_endpoint().port();
  }

  void start() {
    accept();
    thread_ = std::thread([this] { ioc_.run(); });
  }

  void stop() {
    ioc_.stop();
    if (thread_.joinable()) thread_.join();
  }

  void accept() {
    acceptor_.async_accept(net::make_strand(ioc_), [this](beast::error_code ec, tcp::socket s) {
      if (!ec) serve_http(beast::tcp_stream(std::move(s)));
      if (ec != net::error::operation_aborted) accept();
    });
  }

  void serve_http(beast::tcp_stream stream);
  void broadcast(std::shared_ptr<const std::string> frame);

  const Options& options() const { return options_; }
  std::string handle_message(const std::string& text, bool& bad) {
    const auto reply = on_message_(text, bad);
    if (bad) ++stats_bad_;
    return reply;
  }

  net::io_context ioc_{1};
  Options options_;
  OnMessage on_message_;
  tcp::acceptor acceptor_;
  std::uint16_t port_ = 0;
  std::thread thread_;
  std::set<std::shared_ptr<WsSession>> sessions_;  // on the server thread only
  std::atomic<std::uint64_t> clients_{0}, peak_{0}, connections_{0}, refused_{0}, sent_{0}, dropped_{0},
      stats_bad_{0}, http_{0};
};

// What the kernel holds for one client beyond the frame being written
// (Linux doubles it): a few frames at most, so a slow page lags little.
constexpr int kSendBufferBytes = 64 * 1024;

// One WebSocket client: a read loop (requests) and a write loop fed by its Outbox.
class WsSession : public std::enable_shared_from_this<WsSession> {
 public:
  WsSession(beast::tcp_stream stream, Server::Impl* server)
      : ws_(std::move(stream)), server_(std::move(server)) {}

  void accept(http::request<http::string_body> req) {
    beast::get_lowest_layer(ws_).expires_never();
    // The kernel's send buffer, set: left to itself it starts at about 2.6 MB
    // on loopback (ten 64 kB segments, doubled), ten seconds of frames a
    // stalled page would get late before any is dropped.
    beast::error_code ignored;
    beast::get_lowest_layer(ws_).socket().set_option(net::socket_base::send_buffer_size(kSendBufferBytes), ignored);
    ws_.set_option(websocket::stream_base::timeout::suggested(beast::role_type::server));
    ws_.read_message_max(kMaxClientMessage);
    ws_.auto_fragment(false);
    ws_.async_accept(req, [self = shared_from_this()](beast::error_code ec) {
      if (ec) return self->close();
      self->open_ = true;
      self->read();
      self->flush();
    });
  }

  void push_frame(const std::shared_ptr<const std::string>& f) {
    const auto before = outbox_.dropped_frames();
    outbox_.push_frame(f);
    server_->dropped_ += outbox_.dropped_frames() - before;
    flush();
  }

  void close() {
    if (closed_) return;
    closed_ = true;
    --server_->clients_;
    server_->sessions_.erase(shared_from_this());
  }

 private:
  void read() {
    ws_.async_read(buffer_, [self = shared_from_this()](beast::error_code ec, std::size_t) {
      if (ec) return self->close();  // closed, reset, too large, timed out
      if (!self->ws_.got_text()) {
        ++self->server_->stats_bad_;
        self->reply(R"({"type":"error","message":"binary messages are not accepted"})");
      } else {
        bool bad = false;
        const auto r = self->server_->handle_message(beast::buffers_to_string(self->buffer_.data()), bad);
        if (!r.empty()) self->reply(r);
      }
      self->buffer_.consume(self->buffer_.size());
      self->read();
    });
  }

  void reply(std::string text) {
    outbox_.push_reply(std::make_shared<const std::string>(std::move(text)));
    flush();
  }

  void flush() {
    if (!open_ || writing_ || closed_) return;
    auto m = outbox_.take();
    if (!m) return;
    writing_ = true;
    ws_.text(true);
    ws_.async_write(net::buffer(*m), [self = shared_from_this(), m](beast::error_code ec, std::size_t) {
      self->writing_ = false;
      if (ec) return self->close();
      ++self->server_->sent_;
      self->flush();
    });
  }

  websocket::stream<beast::tcp_stream> ws_;
  Server::Impl* server_;  // outlives every session: it owns the io_context
  beast::flat_buffer buffer_;
  Outbox outbox_;
  bool open_ = false, writing_ = false, closed_ = false;
};

// One HTTP connection: files, or the upgrade to a WebSocket on /ws.
class HttpSession : public std::enable_shared_from_this<HttpSession> {
 public:
  HttpSession(beast::tcp_stream stream, Server::Impl* server)
      : stream_(std::move(stream)), server_(std::move(server)) {}

  void read() {
    parser_.emplace();
    parser_->body_limit(16 * 1024);
    parser_->header_limit(16 * 1024);
    stream_.expires_after(std::chrono::seconds(30));
    http::async_read(stream_, buffer_, *parser_, [self = shared_from_this()](beast::error_code ec, std::size_t) {
      if (ec) {
        if (ec != http::error::end_of_stream && ec != beast::error::timeout) {
          // A malformed request: say so, then close.
          self->respond(http::status::bad_request, "text/plain", "bad request: " + ec.message() + "\n", false);
          return;
        }
        beast::error_code ignored;
        self->stream_.socket().shutdown(tcp::socket::shutdown_send, ignored);
        return;
      }
      self->handle(self->parser_->release());
    });
  }

 private:
  void handle(http::request<http::string_body> req) {
    ++server_->http_;
    const std::string target(req.target());
    if (websocket::is_upgrade(req)) {
      if (target != "/ws") return respond(http::status::not_found, "text/plain", "WebSocket endpoint is /ws\n", false);
      if (server_->clients_ >= server_->options().max_clients) {
        ++server_->refused_;
        return respond(http::status::service_unavailable, "text/plain",
                       "too many viewer clients (max_clients " + std::to_string(server_->options().max_clients) + ")\n",
                       false);
      }
      auto ws = std::make_shared<WsSession>(std::move(stream_), server_);
      server_->sessions_.insert(ws);
      const auto n = ++server_->clients_;
      ++server_->connections_;
      auto peak = server_->peak_.load();
      while (n > peak && !server_->peak_.compare_exchange_weak(peak, n)) {
      }
      ws->accept(std::move(req));
      return;
    }
    if (req.method() != http::verb::get && req.method() != http::verb::head)
      return respond(http::status::method_not_allowed, "text/plain", "only GET\n", req.keep_alive());
    std::string path = target.substr(0, target.find('?'));
    if (path == "/") path = "/index.html";
    const auto& assets = server_->options().assets;
    const auto it = assets.find(path.substr(1));
    if (it == assets.end()) return respond(http::status::not_found, "text/plain", "not found: " + path + "\n", req.keep_alive());
    respond(http::status::ok, it->second.content_type, req.method() == http::verb::head ? std::string() : it->second.body,
            req.keep_alive());
  }

  void respond(http::status status, const std::string& type, std::string body, bool keep_alive) {
    auto res = std::make_shared<http::response<http::string_body>>(status, 11);
    res->set(http::field::server, "skelgraph-viewer");
    res->set(http::field::content_type, type);
    res->set(http::field::cache_control, "no-cache");
    res->keep_alive(keep_alive);
    res->body() = std::move(body);
    res->prepare_payload();
    http::async_write(stream_, *res, [self = shared_from_this(), res](beast::error_code ec, std::size_t) {
      if (ec) return;
      if (res->keep_alive()) return self->read();
      beast::error_code ignored;
      self->stream_.socket().shutdown(tcp::socket::shutdown_send, ignored);
    });
  }

  beast::tcp_stream stream_;
  Server::Impl* server_;  // outlives every session: it owns the io_context
  beast::flat_buffer buffer_;
  std::optional<http::request_parser<http::string_body>> parser_;
};

void Server::Impl::serve_http(beast::tcp_stream stream) {
  std::make_shared<HttpSession>(std::move(stream), this)->read();
}

void Server::Impl::broadcast(std::shared_ptr<const std::string> frame) {
  net::post(ioc_, [this, frame = std::move(frame)] {
    // Copy: a failed write inside push_frame may remove its session from the set.
    const auto sessions = sessions_;
    for (const auto& s : sessions) s->push_frame(frame);
  });
}

Server::Server(Options options, OnMessage on_message)
    : impl_(std::make_unique<Impl>(std::move(options), std::move(on_message))) {
  impl_->start();
}

Server::~Server() {
  impl_->stop();
  // What is left (sessions, their pending operations) goes with the io_context, last of Impl's members.
  impl_->sessions_.clear();
}

std::uint16_t Server::port() const { return impl_->port_; }

void Server::broadcast(std::shared_ptr<const std::string> frame) { impl_->broadcast(std::move(frame)); }

ServerStats Server::stats() const {
  ServerStats s;
  s.clients = impl_->clients_;
  s.peak_clients = impl_->peak_;
  s.connections = impl_->connections_;
  s.refused = impl_->refused_;
  s.messages_sent = impl_->sent_;
  s.frames_dropped = impl_->dropped_;
  s.bad_messages = impl_->stats_bad_;
  s.http_requests = impl_->http_;
  return s;
}

}  // namespace skelgraph::viewer
