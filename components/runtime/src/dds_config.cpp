#include "skelgraph/runtime/dds_config.hpp"

#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <sstream>
#include <stdexcept>

namespace skelgraph::runtime {

namespace fs = std::filesystem;

namespace {
const char* env(const char* name) {
  const char* v = std::getenv(name);
  return (v != nullptr && *v != '\0') ? v : nullptr;
}
bool looks_like_path(const std::string& p) {
  return p.find('/') != std::string::npos || fs::path(p).extension() == ".xml";
}
}  // namespace

DdsConfig DdsConfig::from_env() {
  DdsConfig c;
  if (const char* p = env("SKELGRAPH_PROFILE")) c.profile = p;
  if (const char* d = env("SKELGRAPH_DOMAIN")) {
    std::istringstream is(d);
    int v = -1;
    if (!(is >> v) || !is.eof() || v < 0 || v > 232) {
      throw std::runtime_error(std::string("SKELGRAPH_DOMAIN must be a domain id 0..232, got '") + d + "'");
    }
    c.domain = v;
  }
  if (const char* i = env("SKELGRAPH_INTERFACES")) {
    std::stringstream ss(i);
    std::string item;
    while (std::getline(ss, item, ',')) {
      if (!item.empty()) c.interfaces.push_back(item);
    }
  }
  if (const char* d = env("SKELGRAPH_DISCOVERY_SERVERS")) {
    std::stringstream ss(d);
    std::string item;
    while (std::getline(ss, item, ',')) {
      if (!item.empty()) {
        parse_server_address(item);  // fail early, naming the variable's value
        c.discovery_servers.push_back(item);
      }
    }
  }
  if (const char* d = env("SKELGRAPH_SECURITY_DIR")) c.security_dir = d;
  if (const char* h = env("SKELGRAPH_HOST")) {
    c.host = h;
  } else {
    char buf[256] = {};
    c.host = gethostname(buf, sizeof(buf) - 1) == 0 ? buf : "unknown";
  }
  return c;
}

ServerAddress parse_server_address(const std::string& text) {
  const auto colon = text.rfind(':');
  const std::string what = "discovery server '" + text + "': expected IP:PORT (e.g. 192.0.2.10:11811)";
  if (colon == std::string::npos || colon == 0) throw std::runtime_error(what);
  ServerAddress a;
  a.ip = text.substr(0, colon);
  int parts = 0;
  std::stringstream ss(a.ip);
  std::string part;
  while (std::getline(ss, part, '.')) {
    if (part.empty() || part.size() > 3 || part.find_first_not_of("0123456789") != std::string::npos ||
        std::stoi(part) > 255) {
      throw std::runtime_error(what + ": '" + a.ip + "' is not an IPv4 address");
    }
    ++parts;
  }
  if (parts != 4 || a.ip.back() == '.') throw std::runtime_error(what + ": '" + a.ip + "' is not an IPv4 address");
  const std::string port = text.substr(colon + 1);
  if (port.empty() || port.size() > 5 || port.find_first_not_of("0123456789") != std::string::npos ||
      std::stoi(port) < 1 || std::stoi(port) > 65535) {
    throw std::runtime_error(what + ": port '" + port + "' is not 1..65535");
  }
  a.port = std::stoi(port);
  return a;
}

std::string profiles_dir() {
  if (const char* d = env("SKELGRAPH_PROFILES_DIR")) return d;
#ifdef SKELGRAPH_SOURCE_DIR
  const fs::path built_in = fs::path(SKELGRAPH_SOURCE_DIR) / "bringup" / "profiles";
  if (fs::is_directory(built_in)) return built_in.string();
#endif
  return "bringup/profiles";
}

std::string profile_file(const std::string& profile) {
  const fs::path p = looks_like_path(profile) ? fs::path(profile) : fs::path(profiles_dir()) / (profile + ".xml");
  if (!fs::is_regular_file(p)) {
    std::string known;
    std::error_code ec;
    for (const auto& e : fs::directory_iterator(profiles_dir(), ec)) {
      if (e.path().extension() == ".xml") known += (known.empty() ? "" : ", ") + e.path().stem().string();
    }
    throw std::runtime_error("DDS profile '" + profile + "': no file " + p.string() +
                             " (profiles in " + profiles_dir() + ": " + (known.empty() ? "none" : known) + ")");
  }
  return p.string();
}

std::string profile_name(const std::string& profile) {
  return looks_like_path(profile) ? fs::path(profile).stem().string() : profile;
}

}  // namespace skelgraph::runtime
