#include "skelgraph/viewer/access.hpp"

#include <openssl/crypto.h>
#include <openssl/evp.h>
#include <openssl/rand.h>

#include <arpa/inet.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace skelgraph::viewer {

namespace fs = std::filesystem;

bool is_loopback_address(const std::string& address) {
  in_addr v4{};
  if (inet_pton(AF_INET, address.c_str(), &v4) == 1) return (ntohl(v4.s_addr) >> 24) == 127;
  in6_addr v6{};
  if (inet_pton(AF_INET6, address.c_str(), &v6) == 1) return IN6_IS_ADDR_LOOPBACK(&v6);
  throw std::runtime_error("viewer: '" + address + "' is not an IP address");
}

ViewerCredentials find_viewer_credentials(const std::string& dir, const std::string& host) {
  ViewerCredentials c;
  c.dir = fs::absolute(dir).string();
  const fs::path d(c.dir);
  c.ca_file = (d / "ca.pem").string();
  c.cert_file = (d / "viewer" / ("server-" + host + ".pem")).string();
  c.key_file = (d / "viewer" / ("server-" + host + ".key")).string();
  c.tokens_file = (d / "viewer" / "tokens").string();
  if (!fs::is_regular_file(c.ca_file))
    throw std::runtime_error("viewer: no " + c.ca_file + ": not a cell's credentials (skelgraph security init DIR ...)");
  if (!fs::is_regular_file(c.cert_file) || !fs::is_regular_file(c.key_file))
    throw std::runtime_error("viewer: no " + c.cert_file + " (and .key): make the viewer's server certificate with "
                             "`skelgraph security viewer " + dir + " --server " + host +
                             " --address ADDRESS[,NAME...]` (the addresses and names browsers will use)");
  return c;
}

namespace {
std::string to_hex(const unsigned char* bytes, std::size_t n) {
  static const char* hex = "0123456789abcdef";
  std::string out;
  for (std::size_t i = 0; i < n; ++i) {
    out += hex[bytes[i] >> 4];
    out += hex[bytes[i] & 15];
  }
  return out;
}
}  // namespace

std::string sha256_hex(const std::string& text) {
  unsigned char md[EVP_MAX_MD_SIZE];
  unsigned int n = 0;
  if (EVP_Digest(text.data(), text.size(), md, &n, EVP_sha256(), nullptr) != 1)
    throw std::runtime_error("viewer: SHA-256 failed (OpenSSL)");
  return to_hex(md, n);
}

std::string new_token() {
  unsigned char b[32];
  if (RAND_bytes(b, sizeof(b)) != 1) throw std::runtime_error("security: no random bytes (OpenSSL RAND_bytes)");
  return to_hex(b, sizeof(b));
}

std::string token_line(const TokenEntry& e) {
  return e.sha256_hex + " " + std::to_string(e.expires_unix) + " " + e.name;
}

std::vector<TokenEntry> read_tokens(const std::string& path) {
  std::vector<TokenEntry> out;
  std::ifstream in(path);
  if (!in) return out;
  std::string line;
  int n = 0;
  while (std::getline(in, line)) {
    ++n;
    if (line.empty() || line[0] == '#') continue;
    std::istringstream s(line);
    TokenEntry e;
    s >> e.sha256_hex >> e.expires_unix >> e.name;
    const bool hex_ok = e.sha256_hex.size() == 64 && e.sha256_hex.find_first_not_of("0123456789abcdef") == std::string::npos;
    if (!s || !hex_ok || e.name.empty())
      throw std::runtime_error(path + ":" + std::to_string(n) +
                               ": expected '<sha256 hex> <expiry unix seconds> <name>' (skelgraph security token writes it)");
    out.push_back(std::move(e));
  }
  return out;
}

AuthResult check_token(const std::vector<TokenEntry>& tokens, const std::string& token, std::int64_t now_unix) {
  if (token.empty()) return {false, "", "no credentials"};
  const auto h = sha256_hex(token);
  for (const auto& e : tokens) {
    if (CRYPTO_memcmp(h.data(), e.sha256_hex.data(), h.size()) != 0) continue;
    if (now_unix >= e.expires_unix)
      return {false, e.name, "token '" + e.name + "' expired " + std::to_string(now_unix - e.expires_unix) + " s ago"};
    return {true, e.name, ""};
  }
  return {false, "", "unknown token"};
}

namespace {
std::string query_value(const std::string& target, const std::string& key) {
  const auto q = target.find('?');
  if (q == std::string::npos) return "";
  std::istringstream s(target.substr(q + 1));
  std::string kv;
  while (std::getline(s, kv, '&')) {
    if (kv.rfind(key + "=", 0) == 0) return kv.substr(key.size() + 1);
  }
  return "";
}
}  // namespace

RequestToken token_of_request(const std::string& authorization, const std::string& cookie, const std::string& target) {
  if (authorization.rfind("Bearer ", 0) == 0) return {authorization.substr(7), false};
  std::istringstream s(cookie);
  std::string part;
  while (std::getline(s, part, ';')) {
    const auto start = part.find_first_not_of(' ');
    if (start == std::string::npos) continue;
    part = part.substr(start);
    if (part.rfind("skelgraph_token=", 0) == 0) return {part.substr(16), false};
  }
  const auto q = query_value(target, "token");
  return {q, !q.empty()};
}

std::string target_without_token(const std::string& target) {
  const auto q = target.find('?');
  if (q == std::string::npos) return target;
  std::istringstream s(target.substr(q + 1));
  std::string kv, kept;
  while (std::getline(s, kv, '&')) {
    if (kv.rfind("token=", 0) == 0 || kv.empty()) continue;
    kept += (kept.empty() ? "" : "&") + kv;
  }
  return target.substr(0, q) + (kept.empty() ? "" : "?" + kept);
}

AuthResult TokenStore::check(const std::string& token, std::int64_t now_unix) {
  std::lock_guard<std::mutex> lock(mutex_);
  std::error_code ec;
  const auto t = fs::last_write_time(path_, ec);
  const std::int64_t stamp = ec ? -1 : static_cast<std::int64_t>(t.time_since_epoch().count());
  if (!stamp_ || *stamp_ != stamp) {
    stamp_ = stamp;
    error_.clear();
    tokens_.clear();
    try {
      tokens_ = read_tokens(path_);
    } catch (const std::exception& e) {
      error_ = e.what();
    }
  }
  if (!error_.empty()) return {false, "", "tokens file unreadable: " + error_};
  return check_token(tokens_, token, now_unix);
}

}  // namespace skelgraph::viewer
