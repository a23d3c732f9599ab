#pragma once
// Who may look at the cell through the viewer (docs/security.md, "The viewer").
//
// On a loopback address the viewer serves plain HTTP to anyone on that
// machine, as before. On any other address it serves only HTTPS/WSS and only
// to a client that brings one of:
//  - a client certificate signed by the cell's CA with OU=viewer (`skelgraph
//    security viewer DIR --person NAME`), within its validity;
//  - a viewer token of the cell (`skelgraph security token DIR --person NAME`),
//    not expired: in an `Authorization: Bearer` header, the `skelgraph_token`
//    cookie, or once as `?token=` in the page's address (the server then sets
//    the cookie, so the page's own requests and its WebSocket carry it).
// Without the cell's files it refuses to start on such an address.
// No sockets here; OpenSSL's libcrypto for hashes and random bytes.

#include <cstdint>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

namespace skelgraph::viewer {

// 127.0.0.0/8 and ::1. Throws std::runtime_error when `address` is not an IP address.
bool is_loopback_address(const std::string& address);

// The files a secure viewer needs, inside a cell's credentials directory.
struct ViewerCredentials {
  std::string dir;
  std::string ca_file;      // DIR/ca.pem: client certificates must be signed by it
  std::string cert_file;    // DIR/viewer/server-HOST.pem: what the viewer shows browsers
  std::string key_file;     // DIR/viewer/server-HOST.key
  std::string tokens_file;  // DIR/viewer/tokens (may be absent: certificates only)
};
// The files for the viewer on `host`. Throws std::runtime_error naming the
// missing file and the command that makes it.
ViewerCredentials find_viewer_credentials(const std::string& dir, const std::string& host);

// One line of the tokens file: "<sha256 of the token, hex> <expiry, unix seconds> <name>".
// Only the hash is kept: the token itself is shown once, when it is made.
struct TokenEntry {
  std::string sha256_hex;
  std::int64_t expires_unix = 0;
  std::string name;
};
std::string sha256_hex(const std::string& text);
std::string new_token();  // 32 random bytes (OpenSSL's RAND_bytes), as 64 hex digits
std::string token_line(const TokenEntry& e);
// Throws std::runtime_error naming file:line and what was expected; an absent file is empty.
std::vector<TokenEntry> read_tokens(const std::string& path);

struct AuthResult {
  bool ok = false;
  std::string who;     // the token's or certificate's name
  std::string reason;  // when refused: "no credentials", "unknown token", "token 'x' expired ..."
};
// Compares hashes in constant time.
AuthResult check_token(const std::vector<TokenEntry>& tokens, const std::string& token, std::int64_t now_unix);

// The token a request carries (header first, then cookie, then the query) and
// whether it came in the query (the page's first request: the reply sets the cookie).
struct RequestToken {
  std::string token;
  bool from_query = false;
};
RequestToken token_of_request(const std::string& authorization, const std::string& cookie, const std::string& target);
// The request target without a token=... query parameter (what the browser is sent on to).
std::string target_without_token(const std::string& target);

// The tokens file, read again when it changes (a token made while the viewer
// runs works at once; one removed from the file stops working). Thread-safe.
class TokenStore {
 public:
  explicit TokenStore(std::string path) : path_(std::move(path)) {}
  AuthResult check(const std::string& token, std::int64_t now_unix);

 private:
  std::string path_;
  std::mutex mutex_;
  std::optional<std::int64_t> stamp_;  // the file's mtime (ns) at the last read; -1: absent
  std::vector<TokenEntry> tokens_;
  std::string error_;  // the file could not be read: every token refused, with this reason
};

}  // namespace skelgraph::viewer
