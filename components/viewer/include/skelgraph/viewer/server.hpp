#pragma once
// The viewer's web server: serves the page (files held in memory, nothing read
// from disk per request, nothing outside them reachable) and streams frames to
// every WebSocket client on /ws. One thread of its own (Boost.Beast on
// Boost.Asio); the graph's threads only hand it frames (broadcast()), so a
// slow, broken or hostile client never holds up the graph: each client keeps
// only the newest unsent frame (Outbox), messages are size-limited, and
// clients beyond max_clients are refused with HTTP 503.

#include <atomic>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>

namespace skelgraph::viewer {

struct Asset {
  std::string body;
  std::string content_type;
};

// (See access.hpp for who may connect when the viewer is secure.)

// Every regular file under `dir`, keyed by its path from there ("index.html",
// "three/three.module.js"). Throws std::runtime_error naming the folder when it
// has no index.html.
std::map<std::string, Asset> load_assets(const std::string& dir);

struct ServerStats {
  std::uint64_t clients = 0;       // WebSocket clients connected now
  std::uint64_t peak_clients = 0;
  std::uint64_t connections = 0;   // WebSocket clients accepted since start
  std::uint64_t refused = 0;       // refused: max_clients reached
  std::uint64_t messages_sent = 0; // frames and replies, summed over clients
  std::uint64_t frames_dropped = 0;  // not sent because a newer frame came first (slow clients)
  std::uint64_t bad_messages = 0;  // malformed client messages answered with an error
  std::uint64_t http_requests = 0;
  // Secure viewers only (Options::tls):
  std::uint64_t tls_refused = 0;   // TLS handshakes that failed: no TLS at all, a certificate of another CA, expired
  std::uint64_t tls_abandoned = 0; // connections the client closed before its handshake (browsers' spare ones)
  std::uint64_t auth_refused = 0;  // requests without a valid certificate or token (HTTP 401)
  std::uint64_t by_certificate = 0, by_token = 0;  // requests let in, by how
  std::string last_refusal;        // why the last one was refused, and from where
};

class Server {
 public:
  struct Options {
    std::string address = "127.0.0.1";
    std::uint16_t port = 8080;  // 0: any free port (see port())
    std::size_t max_clients = 64;
    std::map<std::string, Asset> assets;
    // Set: HTTPS/WSS only, and every request must bring a client certificate
    // (signed by ca_file, OU=viewer) or a token from tokens_file (access.hpp).
    struct Tls {
      std::string cert_file, key_file, ca_file, tokens_file;
    };
    std::optional<Tls> tls;
  };
  // Called on the server's thread for each text message from a client; returns
  // the reply to send to that client ("" for none). `bad` is set when the
  // message was refused (counted in bad_messages).
  using OnMessage = std::function<std::string(const std::string& text, bool& bad)>;

  // Binds and listens; throws std::runtime_error with the address when it cannot.
  Server(Options options, OnMessage on_message);
  ~Server();
  Server(const Server&) = delete;
  Server& operator=(const Server&) = delete;

  std::uint16_t port() const;
  // Thread-safe: every client gets this frame (or a newer one).
  void broadcast(std::shared_ptr<const std::string> frame);
  ServerStats stats() const;

  class Impl;

 private:
  std::unique_ptr<Impl> impl_;
};

}  // namespace skelgraph::viewer
