#include "skelgraph/viewer/server.hpp"

#include <chrono>
#include <filesystem>
#include <mutex>
#include <fstream>
#include <optional>
#include <set>
#include <sstream>
#include <stdexcept>
#include <thread>

#include <boost/asio.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/ssl.hpp>
#include <boost/beast/websocket.hpp>
#include <boost/beast/websocket/ssl.hpp>
#include <openssl/ssl.h>
#include <openssl/x509.h>

#include "skelgraph/viewer/access.hpp"
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


namespace {

using TlsStream = beast::ssl_stream<beast::tcp_stream>;

// Closes the sending side: a plain TCP shutdown, or TLS's close_notify first.
void shutdown_send(beast::tcp_stream& s, std::shared_ptr<void>) {
  beast::error_code ignored;
  s.socket().shutdown(tcp::socket::shutdown_send, ignored);
}
void shutdown_send(TlsStream& s, std::shared_ptr<void> keep) {
  beast::get_lowest_layer(s).expires_after(std::chrono::seconds(5));
  s.async_shutdown([keep](beast::error_code) {});
}

// The CN of a client certificate that OpenSSL verified against the cell's CA
// and that was issued for the viewer (OU=viewer); "" otherwise.
std::string viewer_certificate_name(SSL* ssl) {
  if (SSL_get_verify_result(ssl) != X509_V_OK) return "";
  X509* cert = SSL_get1_peer_certificate(ssl);
  if (!cert) return "";
  const auto field = [&](int nid) {
    X509_NAME* name = X509_get_subject_name(cert);
    const int i = X509_NAME_get_index_by_NID(name, nid, -1);
    if (i < 0) return std::string();
    const ASN1_STRING* v = X509_NAME_ENTRY_get_data(X509_NAME_get_entry(name, i));
    return std::string(reinterpret_cast<const char*>(ASN1_STRING_get0_data(v)), static_cast<std::size_t>(ASN1_STRING_length(v)));
  };
  const std::string ou = field(NID_organizationalUnitName), cn = field(NID_commonName);
  X509_free(cert);
  return ou == "viewer" && !cn.empty() ? cn : "";
}

std::string peer_of(const beast::tcp_stream& s) {
  beast::error_code ec;
  const auto ep = s.socket().remote_endpoint(ec);
  return ec ? "?" : ep.address().to_string() + ":" + std::to_string(ep.port());
}

}  // namespace

class WsClient : public std::enable_shared_from_this<WsClient> {
 public:
  virtual ~WsClient() = default;
  virtual void push_frame(const std::shared_ptr<const std::string>& f) = 0;
};

class Server::Impl {
 public:
  Impl(Options o, OnMessage on_message)
      : options_(std::move(o)), on_message_(std::move(on_message)), acceptor_(ioc_) {
    if (options_.tls) setup_tls(*options_.tls);
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

  void setup_tls(const Options::Tls& t) {
    ssl_.emplace(net::ssl::context::tls_server);
    auto& c = *ssl_;
    c.set_options(net::ssl::context::default_workarounds | net::ssl::context::no_sslv2 | net::ssl::context::no_sslv3 |
                  net::ssl::context::no_tlsv1 | net::ssl::context::no_tlsv1_1);
    const auto load = [](const std::string& what, const std::string& file, auto&& f) {
      beast::error_code ec;
      f(ec);
      if (ec) throw std::runtime_error("viewer: cannot use " + what + " " + file + ": " + ec.message());
    };
    load("the certificate", t.cert_file, [&](beast::error_code& ec) { c.use_certificate_chain_file(t.cert_file, ec); });
    load("the key", t.key_file, [&](beast::error_code& ec) { c.use_private_key_file(t.key_file, net::ssl::context::pem, ec); });
    load("the CA", t.ca_file, [&](beast::error_code& ec) { c.load_verify_file(t.ca_file, ec); });
    if (SSL_CTX_check_private_key(c.native_handle()) != 1)
      throw std::runtime_error("viewer: " + t.key_file + " is not the key of " + t.cert_file);
    // A server that asks for client certificates needs a session id context,
    // or every resumed session (browsers resume on their parallel connections) fails.
    static const unsigned char kSessionContext[] = "skelgraph-viewer";
    SSL_CTX_set_session_id_context(c.native_handle(), kSessionContext, sizeof(kSessionContext) - 1);
    // Browsers are told which CA's certificates to offer.
    if (STACK_OF(X509_NAME)* names = SSL_load_client_CA_file(t.ca_file.c_str()))
      SSL_CTX_set_client_CA_list(c.native_handle(), names);
    // A certificate is asked for, not required: without one a token must come.
    // One that does not verify (another CA, expired) ends the handshake.
    c.set_verify_mode(net::ssl::verify_peer);
    c.set_verify_callback([this](bool preverified, net::ssl::verify_context& v) {
      if (!preverified) {
        const int err = X509_STORE_CTX_get_error(v.native_handle());
        std::lock_guard<std::mutex> lock(refusal_mutex_);
        pending_cert_error_ = X509_verify_cert_error_string(err);
      }
      return preverified;
    });
    tokens_.emplace(t.tokens_file);
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
      if (!ec) serve(beast::tcp_stream(std::move(s)));
      if (ec != net::error::operation_aborted) accept();
    });
  }

  void serve(beast::tcp_stream stream);
  void broadcast(std::shared_ptr<const std::string> frame);

  const Options& options() const { return options_; }
  bool secure() const { return ssl_.has_value(); }
  std::string handle_message(const std::string& text, bool& bad) {
    const auto reply = on_message_(text, bad);
    if (bad) ++stats_bad_;
    return reply;
  }
  void refuse(std::atomic<std::uint64_t>& counter, const std::string& why) {
    ++counter;
    std::lock_guard<std::mutex> lock(refusal_mutex_);
    last_refusal_ = why;
  }
  std::string take_cert_error() {
    std::lock_guard<std::mutex> lock(refusal_mutex_);
    return std::exchange(pending_cert_error_, std::string());
  }
  std::string last_refusal() const {
    std::lock_guard<std::mutex> lock(refusal_mutex_);
    return last_refusal_;
  }
  // A secure viewer's check of one request: who it is, or "" (refused, counted, `why` says why).
  std::string authenticate(const std::string& cert_name, const RequestToken& token, const std::string& peer,
                           std::string& why) {
    if (!cert_name.empty()) {
      ++by_certificate_;
      return "certificate " + cert_name;
    }
    const auto now = std::chrono::duration_cast<std::chrono::seconds>(std::chrono::system_clock::now().time_since_epoch()).count();
    const auto r = tokens_->check(token.token, now);
    if (r.ok) {
      ++by_token_;
      return "token " + r.who;
    }
    why = r.reason;
    refuse(auth_refused_, peer + ": " + r.reason);
    return "";
  }

  net::io_context ioc_{1};
  Options options_;
  OnMessage on_message_;
  std::optional<net::ssl::context> ssl_;
  std::optional<TokenStore> tokens_;
  tcp::acceptor acceptor_;
  std::uint16_t port_ = 0;
  std::thread thread_;
  std::set<std::shared_ptr<WsClient>> sessions_;  // on the server thread only
  std::atomic<std::uint64_t> clients_{0}, peak_{0}, connections_{0}, refused_{0}, sent_{0}, dropped_{0},
      stats_bad_{0}, http_{0}, tls_refused_{0}, tls_abandoned_{0}, auth_refused_{0}, by_certificate_{0}, by_token_{0};
  mutable std::mutex refusal_mutex_;
  std::string last_refusal_, pending_cert_error_;
};

// What the kernel holds for one client beyond the frame being written
// (Linux doubles it): a few frames at most, so a slow page lags little.
constexpr int kSendBufferBytes = 64 * 1024;

// One WebSocket client: a read loop (requests) and a write loop fed by its Outbox.
template <class Stream>
class WsSession : public WsClient {
 public:
  WsSession(Stream stream, Server::Impl* server) : ws_(std::move(stream)), server_(server) {}

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
    ws_.async_accept(req, [self = self()](beast::error_code ec) {
      if (ec) return self->close();
      self->open_ = true;
      self->read();
      self->flush();
    });
  }

  void push_frame(const std::shared_ptr<const std::string>& f) override {
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
  std::shared_ptr<WsSession> self() { return std::static_pointer_cast<WsSession>(shared_from_this()); }

  void read() {
    ws_.async_read(buffer_, [self = self()](beast::error_code ec, std::size_t) {
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
    ws_.async_write(net::buffer(*m), [self = self(), m](beast::error_code ec, std::size_t) {
      self->writing_ = false;
      if (ec) return self->close();
      ++self->server_->sent_;
      self->flush();
    });
  }

  websocket::stream<Stream> ws_;
  Server::Impl* server_;  // outlives every session: it owns the io_context
  beast::flat_buffer buffer_;
  Outbox outbox_;
  bool open_ = false, writing_ = false, closed_ = false;
};

// One HTTP connection: files, or the upgrade to a WebSocket on /ws. On a
// secure viewer every request is authenticated first (access.hpp).
template <class Stream>
class HttpSession : public std::enable_shared_from_this<HttpSession<Stream>> {
 public:
  HttpSession(Stream stream, Server::Impl* server, std::string cert_name = {})
      : stream_(std::move(stream)), server_(server), cert_name_(std::move(cert_name)) {}

  void read() {
    parser_.emplace();
    parser_->body_limit(16 * 1024);
    parser_->header_limit(16 * 1024);
    beast::get_lowest_layer(stream_).expires_after(std::chrono::seconds(30));
    http::async_read(stream_, buffer_, *parser_, [self = this->shared_from_this()](beast::error_code ec, std::size_t) {
      if (ec) {
        if (ec != http::error::end_of_stream && ec != beast::error::timeout) {
          // A malformed request: say so, then close.
          self->respond(http::status::bad_request, "text/plain", "bad request: " + ec.message() + "\n", false);
          return;
        }
        shutdown_send(self->stream_, self);
        return;
      }
      self->handle(self->parser_->release());
    });
  }

 private:
  void handle(http::request<http::string_body> req) {
    ++server_->http_;
    std::string target(req.target());
    std::string set_cookie;
    if (server_->secure()) {
      const auto token = token_of_request(std::string(req[http::field::authorization]),
                                          std::string(req[http::field::cookie]), target);
      std::string why;
      if (server_->authenticate(cert_name_, token, peer_of(beast::get_lowest_layer(stream_)), why).empty())
        return respond(http::status::unauthorized, "text/plain",
                       "this viewer needs a client certificate or a token of the cell (" + why +
                           "): skelgraph security viewer DIR --person NAME, or skelgraph security token DIR --person NAME; "
                           "then open https://HOST:PORT/?token=TOKEN\n",
                       false);
      // The token came in the address: set the cookie and send the browser on
      // without it (out of the address bar and the history).
      if (token.from_query && !websocket::is_upgrade(req))
        return redirect(target_without_token(target),
                        "skelgraph_token=" + token.token + "; Secure; HttpOnly; SameSite=Strict; Path=/",
                        req.keep_alive());
    }
    if (websocket::is_upgrade(req)) {
      if (target.substr(0, target.find('?')) != "/ws")
        return respond(http::status::not_found, "text/plain", "WebSocket endpoint is /ws\n", false);
      if (server_->clients_ >= server_->options().max_clients) {
        ++server_->refused_;
        return respond(http::status::service_unavailable, "text/plain",
                       "too many viewer clients (max_clients " + std::to_string(server_->options().max_clients) + ")\n",
                       false);
      }
      auto ws = std::make_shared<WsSession<Stream>>(std::move(stream_), server_);
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

  void redirect(const std::string& location, const std::string& cookie, bool keep_alive) {
    auto res = make_response(http::status::see_other, "text/plain", "see " + location + "\n", keep_alive);
    res->set(http::field::location, location);
    res->set(http::field::set_cookie, cookie);
    send(res);
  }

  void respond(http::status status, const std::string& type, std::string body, bool keep_alive) {
    send(make_response(status, type, std::move(body), keep_alive));
  }

  std::shared_ptr<http::response<http::string_body>> make_response(http::status status, const std::string& type,
                                                                    std::string body, bool keep_alive) {
    auto res = std::make_shared<http::response<http::string_body>>(status, 11);
    res->set(http::field::server, "skelgraph-viewer");
    res->set(http::field::content_type, type);
    res->set(http::field::cache_control, "no-cache");
    if (server_->secure()) res->set("Strict-Transport-Security", "max-age=31536000");
    res->keep_alive(keep_alive);
    res->body() = std::move(body);
    res->prepare_payload();
    return res;
  }

  void send(std::shared_ptr<http::response<http::string_body>> res) {
    http::async_write(stream_, *res, [self = this->shared_from_this(), res](beast::error_code ec, std::size_t) {
      if (ec) return;
      if (res->keep_alive()) return self->read();
      shutdown_send(self->stream_, self);
    });
  }

  Stream stream_;
  Server::Impl* server_;  // outlives every session: it owns the io_context
  std::string cert_name_;  // a verified viewer certificate's name (secure viewer), else ""
  beast::flat_buffer buffer_;
  std::optional<http::request_parser<http::string_body>> parser_;
};

void Server::Impl::serve(beast::tcp_stream stream) {
  if (!secure()) {
    std::make_shared<HttpSession<beast::tcp_stream>>(std::move(stream), this)->read();
    return;
  }
  // TLS first: nothing is read or served in the clear.
  const std::string peer = peer_of(stream);
  auto tls = std::make_shared<TlsStream>(std::move(stream), *ssl_);
  beast::get_lowest_layer(*tls).expires_after(std::chrono::seconds(10));
  tls->async_handshake(net::ssl::stream_base::server, [this, tls, peer](beast::error_code ec) {
    const auto cert_error = take_cert_error();
    if (ec && cert_error.empty() && (ec == net::ssl::error::stream_truncated || ec == net::error::eof)) {
      ++tls_abandoned_;  // closed by the browser before it said anything (its spare connections): not a refusal
      return;
    }
    if (ec) {
      refuse(tls_refused_, peer + ": TLS handshake failed: " + (cert_error.empty() ? ec.message() : "client certificate: " + cert_error));
      beast::error_code ignored;
      beast::get_lowest_layer(*tls).socket().close(ignored);
      return;
    }
    const auto name = viewer_certificate_name(tls->native_handle());
    std::make_shared<HttpSession<TlsStream>>(std::move(*tls), this, name)->read();
  });
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
  s.tls_refused = impl_->tls_refused_;
  s.tls_abandoned = impl_->tls_abandoned_;
  s.auth_refused = impl_->auth_refused_;
  s.by_certificate = impl_->by_certificate_;
  s.by_token = impl_->by_token_;
  s.last_refusal = impl_->last_refusal();
  return s;
}

}  // namespace skelgraph::viewer
