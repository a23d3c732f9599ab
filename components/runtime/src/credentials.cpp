#include "skelgraph/runtime/credentials.hpp"

#include <fcntl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "skelgraph/runtime/topics.hpp"
#include "skelgraph/viewer/access.hpp"

namespace skelgraph::runtime::security {

namespace fs = std::filesystem;

namespace {

// Runs openssl with `args` in `dir`; returns its output (stdout and stderr), throws with it on failure.
std::string openssl(const fs::path& dir, const std::vector<std::string>& args) {
  const fs::path log = dir / ".openssl.log";
  const pid_t pid = fork();
  if (pid < 0) throw std::runtime_error("security: cannot start openssl");
  if (pid == 0) {
    if (chdir(dir.c_str()) != 0) _exit(126);
    const int fd = open(log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0600);
    if (fd >= 0) {
      dup2(fd, 1);
      dup2(fd, 2);
    }
    std::vector<char*> argv;
    std::string prog = "openssl";
    argv.push_back(prog.data());
    std::vector<std::string> copy = args;
    for (auto& a : copy) argv.push_back(a.data());
    argv.push_back(nullptr);
    execvp("openssl", argv.data());
    _exit(127);
  }
  int status = 0;
  waitpid(pid, &status, 0);
  std::ifstream in(log);
  std::stringstream out;
  out << in.rdbuf();
  fs::remove(log);
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
    std::string cmd = "openssl";
    for (const auto& a : args) cmd += " " + a;
    if (WIFEXITED(status) && WEXITSTATUS(status) == 127) {
      throw std::runtime_error("security: the openssl program is not installed (Debian: apt install openssl)");
    }
    throw std::runtime_error("security: `" + cmd + "` failed:\n" + out.str());
  }
  return out.str();
}

void write_file(const fs::path& p, const std::string& text, fs::perms perms = fs::perms::owner_read | fs::perms::owner_write |
                                                                               fs::perms::group_read | fs::perms::others_read) {
  std::ofstream out(p);
  out << text;
  if (!out) throw std::runtime_error("security: cannot write " + p.string());
  out.close();
  fs::permissions(p, perms);
}

std::string utc(std::chrono::system_clock::time_point t) {
  const std::time_t tt = std::chrono::system_clock::to_time_t(t);
  std::tm tm{};
  gmtime_r(&tt, &tm);
  char buf[32];
  std::strftime(buf, sizeof(buf), "%Y-%m-%dT%H:%M:%S", &tm);
  return buf;
}

std::string joined(const std::vector<std::string>& v, const char* sep = "+") {
  std::string out;
  for (const auto& s : v) out += (out.empty() ? "" : sep) + s;
  return out;
}


fs::path cell_dir(const std::string& d) {
  const fs::path dir = fs::absolute(d);
  if (!fs::is_regular_file(dir / "ca.pem") || !fs::is_regular_file(dir / "ca.key"))
    throw CredentialsError(dir.string() + " holds no cell CA (ca.pem and ca.key): make one with skelgraph security init");
  fs::create_directories(dir / "viewer" / "people");
  fs::permissions(dir / "viewer", fs::perms::owner_all, fs::perm_options::replace);
  return dir;
}

}  // namespace

Hosts hosts_of(const CellSpec& o) {
  // A host may hold several roles (the fusion host as master and robot-control).
  Hosts hosts;
  const auto add = [&](const std::string& h, const std::string& role) {
    if (!valid_host(h)) throw CredentialsError("host name '" + h + "': letters, digits, '-', '_' and '.' only (1-64)");
    for (auto& [name, roles] : hosts) {
      if (name != h) continue;
      if (std::find(roles.begin(), roles.end(), role) != roles.end()) throw CredentialsError("host '" + h + "' named twice as " + role);
      roles.push_back(role);
      return;
    }
    hosts.push_back({h, {role}});
  };
  add(o.master, "master");
  for (const auto& h : o.sensors) add(h, "sensor");
  for (const auto& h : o.readers) add(h, "reader");
  for (const auto& h : o.robots) add(h, "robot");
  for (const auto& h : o.robot_control) add(h, "robot-control");
  for (const auto& [h, roles] : hosts)
    if (roles.size() > 1 && std::find(roles.begin(), roles.end(), "reader") != roles.end())
      throw CredentialsError("host '" + h + "' is a reader and " + joined(roles, ", ") + ": a reader has no other role");
  return hosts;
}

nlohmann::json make_cell_credentials(const std::string& dir_name, const CellSpec& o) {
  const auto hosts = hosts_of(o);
  const fs::path dir = fs::absolute(dir_name);
  if (fs::exists(dir / "ca.key") && !o.force) {
    throw CredentialsError(dir.string() + " already holds a CA (ca.key): use --force to make a new cell (every host then "
                     "needs the new files), or another directory");
  }
  fs::create_directories(dir / "hosts");
  fs::permissions(dir, fs::perms::owner_all, fs::perm_options::replace);
  const std::string days = std::to_string(o.days);
  // The CA: its key usage includes digitalSignature, without which Fast DDS
  // cannot verify the governance and permissions it signs (and says only
  // that the participant could not be created).
  write_file(dir / "openssl.cnf", R"([req]
distinguished_name = dn
prompt = no
[dn]
CN = skelgraph cell CA
[v3_ca]
basicConstraints = critical, CA:TRUE
keyUsage = critical, digitalSignature, keyCertSign, cRLSign
subjectKeyIdentifier = hash
[v3_host]
basicConstraints = critical, CA:FALSE
keyUsage = critical, digitalSignature, keyAgreement
authorityKeyIdentifier = keyid
)");
  openssl(dir, {"ecparam", "-name", "prime256v1", "-genkey", "-noout", "-out", "ca.key"});
  fs::permissions(dir / "ca.key", fs::perms::owner_read | fs::perms::owner_write, fs::perm_options::replace);
  openssl(dir, {"req", "-x509", "-new", "-key", "ca.key", "-config", "openssl.cnf", "-extensions", "v3_ca", "-days",
                days, "-sha256", "-out", "ca.pem"});
  for (const auto& [h, roles] : hosts) {
    const std::string key = "hosts/" + h + ".key", csr = "hosts/" + h + ".csr", pem = "hosts/" + h + ".pem";
    openssl(dir, {"ecparam", "-name", "prime256v1", "-genkey", "-noout", "-out", key});
    fs::permissions(dir / key, fs::perms::owner_read | fs::perms::owner_write, fs::perm_options::replace);
    openssl(dir, {"req", "-new", "-key", key, "-subj", "/CN=" + h, "-out", csr});
    openssl(dir, {"x509", "-req", "-in", csr, "-CA", "ca.pem", "-CAkey", "ca.key", "-CAcreateserial", "-extfile",
                  "openssl.cnf", "-extensions", "v3_host", "-days", days, "-sha256", "-out", pem});
    fs::remove(dir / csr);
  }
  const auto now = std::chrono::system_clock::now();
  write_file(dir / "governance.xml", governance_xml());
  write_file(dir / "permissions.xml",
             permissions_xml(hosts, utc(now - std::chrono::hours(24)), utc(now + std::chrono::hours(24) * o.days)));
  for (const auto* doc : {"governance", "permissions"}) {
    openssl(dir, {"smime", "-sign", "-in", std::string(doc) + ".xml", "-text", "-out", std::string(doc) + ".p7s",
                  "-signer", "ca.pem", "-inkey", "ca.key"});
  }
  nlohmann::json out = {{"directory", dir.string()}, {"hosts", nlohmann::json::object()}};
  nlohmann::json roles_file = nlohmann::json::object();
  for (const auto& [h, roles] : hosts) {
    const auto g = grant_of(roles);
    out["hosts"][h] = {{"role", joined(roles)}, {"roles", roles}, {"publishes", g.publish}, {"denied", g.deny}};
    roles_file[h] = roles;
  }
  write_file(dir / "roles.json", roles_file.dump(2) + "\n");
  return out;
}

nlohmann::json check_cell_credentials(const std::string& dir_name, const std::string& host) {
  const fs::path dir = fs::absolute(dir_name);
  nlohmann::json out = {{"directory", dir.string()}, {"ok", true}, {"checks", nlohmann::json::array()}};
  const auto record = [&](const std::string& what, bool ok, const std::string& detail) {
    out["checks"].push_back({{"check", what}, {"ok", ok}, {"detail", detail}});
    if (!ok) out["ok"] = false;
  };
  const auto attempt = [&](const std::string& what, const std::vector<std::string>& args) {
    try {
      const auto text = openssl(dir, args);
      record(what, true, text.substr(0, text.find('\n')));
    } catch (const std::exception& e) {
      record(what, false, e.what());
    }
  };
  for (const auto* f : {"ca.pem", "governance.p7s", "permissions.p7s"}) {
    if (!fs::is_regular_file(dir / f)) record(std::string("file ") + f, false, "missing (skelgraph security init)");
  }
  if (fs::is_regular_file(dir / "ca.pem")) {
    try {
      const auto text = openssl(dir, {"x509", "-in", "ca.pem", "-noout", "-ext", "keyUsage"});
      record("CA key usage includes digitalSignature", text.find("Digital Signature") != std::string::npos,
             "needed to verify the signed governance and permissions");
    } catch (const std::exception& e) {
      record("CA certificate readable", false, e.what());
    }
    for (const auto* doc : {"governance", "permissions"}) {
      attempt(std::string(doc) + ".p7s signed by ca.pem",
              {"smime", "-verify", "-in", std::string(doc) + ".p7s", "-CAfile", "ca.pem", "-out", "/dev/null"});
    }
  }
  std::vector<std::string> hosts;
  if (!host.empty()) {
    hosts.push_back(host);
  } else if (fs::is_directory(dir / "hosts")) {
    for (const auto& e : fs::directory_iterator(dir / "hosts")) {
      if (e.path().extension() == ".pem") hosts.push_back(e.path().stem().string());
    }
  }
  std::string permissions;
  if (std::ifstream in{dir / "permissions.xml"}) {
    std::stringstream ss;
    ss << in.rdbuf();
    permissions = ss.str();
  }
  nlohmann::json roles_file = nlohmann::json::object();
  if (std::ifstream in{dir / "roles.json"}) {
    try {
      in >> roles_file;
    } catch (const std::exception& e) {
      record("roles.json", false, e.what());
    }
  }
  out["hosts"] = nlohmann::json::object();
  for (const auto& h : hosts) {
    if (!fs::is_regular_file(dir / "hosts" / (h + ".pem")) || !fs::is_regular_file(dir / "hosts" / (h + ".key"))) {
      record("host " + h, false, "no hosts/" + h + ".pem and .key");
      continue;
    }
    attempt("host " + h + ": certificate signed by ca.pem", {"verify", "-CAfile", "ca.pem", "hosts/" + h + ".pem"});
    const auto begin = permissions.find("<grant name=\"" + h + "\">");
    const auto end = permissions.find("</grant>", begin);
    const std::string grant = begin == std::string::npos ? "" : permissions.substr(begin, end - begin);
    record("host " + h + ": granted in permissions.xml",
           grant.find("<subject_name>CN=" + h + "</subject_name>") != std::string::npos, "a grant for subject CN=" + h);
    if (!roles_file.contains(h)) {
      record("host " + h + ": roles", false, "not in roles.json (credentials made before roles were written: make them again)");
      continue;
    }
    const auto roles = roles_file[h].get<std::vector<std::string>>();
    const auto g = grant_of(roles);
    const auto topics = [](const std::vector<std::string>& v) {
      std::string s = "<publish><topics>";
      for (const auto& t : v) s += "<topic>" + t + "</topic>";
      return s + "</topics></publish>";
    };
    const bool allow_ok = grant.find("<allow_rule>") != std::string::npos &&
                          grant.find(topics(g.publish), grant.find("<allow_rule>")) != std::string::npos;
    const bool deny_ok = g.deny.empty() ? grant.find("<deny_rule>") == std::string::npos
                                        : grant.find(topics(g.deny)) != std::string::npos &&
                                              grant.find("<deny_rule>") < grant.find("<allow_rule>");
    const bool robot_command = std::find(g.publish.begin(), g.publish.end(), runtime::topics::kRobotCommand.name) != g.publish.end();
    record("host " + h + ": roles " + joined(roles) + " as granted (robot commands: " + (robot_command ? "yes" : "no") + ")",
           allow_ok && deny_ok, "the grant's publish and deny rules are not what the roles give");
    out["hosts"][h] = {{"roles", roles}, {"publishes", g.publish}, {"denied", g.deny}, {"robot_commands", robot_command}};
  }
  return out;
}

nlohmann::json make_viewer_certificate(const std::string& cell, const ViewerCertSpec& o) {
  if (o.server.empty() == o.person.empty()) throw CredentialsError("give either --server HOST or --person NAME");
  const bool server = !o.server.empty();
  const std::string name = server ? o.server : o.person;
  if (!valid_host(name)) throw CredentialsError("name '" + name + "': letters, digits, '-', '_' and '.' only (1-64)");
  if (server && o.addresses.empty())
    throw CredentialsError("--server needs --address: the IP addresses and names browsers will use to reach the viewer");
  const fs::path dir = cell_dir(cell);
  const int days = o.days > 0 ? o.days : server ? 825 : 90;
  const std::string san = subject_alt_names(o.addresses);
  const std::string stem = server ? "viewer/server-" + name : "viewer/people/" + name;
  const std::string ext = stem + ".ext.cnf";
  write_file(dir / ext, std::string("[v3]\nbasicConstraints = critical, CA:FALSE\nkeyUsage = critical, digitalSignature\n") +
                            "extendedKeyUsage = " + (server ? "serverAuth" : "clientAuth") + "\n" +
                            (san.empty() ? "" : "subjectAltName = " + san + "\n") +
                            "authorityKeyIdentifier = keyid\n");
  openssl(dir, {"ecparam", "-name", "prime256v1", "-genkey", "-noout", "-out", stem + ".key"});
  fs::permissions(dir / (stem + ".key"), fs::perms::owner_read | fs::perms::owner_write, fs::perm_options::replace);
  openssl(dir, {"req", "-new", "-key", stem + ".key", "-subj", "/CN=" + name + "/OU=" + (server ? "viewer-server" : "viewer"),
                "-out", stem + ".csr"});
  openssl(dir, {"x509", "-req", "-in", stem + ".csr", "-CA", "ca.pem", "-CAkey", "ca.key", "-CAcreateserial", "-extfile",
                ext, "-extensions", "v3", "-days", std::to_string(days), "-sha256", "-out", stem + ".pem"});
  fs::remove(dir / (stem + ".csr"));
  fs::remove(dir / ext);
  nlohmann::json out = {{"kind", server ? "server" : "person"}, {"name", name}, {"days", days},
                        {"certificate", (dir / (stem + ".pem")).string()}, {"key", (dir / (stem + ".key")).string()}};
  if (server) out["addresses"] = o.addresses;
  if (!server) {
    // For a browser's certificate store: certificate, key and the CA in one file, no password.
    openssl(dir, {"pkcs12", "-export", "-in", stem + ".pem", "-inkey", stem + ".key", "-certfile", "ca.pem", "-name",
                  "skelgraph viewer " + name, "-passout", "pass:", "-out", stem + ".p12"});
    fs::permissions(dir / (stem + ".p12"), fs::perms::owner_read | fs::perms::owner_write, fs::perm_options::replace);
    out["pkcs12"] = (dir / (stem + ".p12")).string();
  }
  return out;
}

std::string subject_alt_names(const std::vector<std::string>& addresses) {
  std::string san;
  for (const auto& a : addresses) {
    bool ip = false;
    try {
      viewer::is_loopback_address(a);
      ip = true;
    } catch (const std::exception&) {
      if (!valid_host(a)) throw CredentialsError("--address '" + a + "': an IP address or a host name");
    }
    san += (san.empty() ? "" : ",") + std::string(ip ? "IP:" : "DNS:") + a;
  }
  return san;
}

std::string tokens_file(const std::string& dir) { return (fs::absolute(dir) / "viewer" / "tokens").string(); }

nlohmann::json viewer_token(const std::string& cell, const std::string& person, const std::string& revoke, int days_wanted) {
  const fs::path dir = cell_dir(cell);
  const std::string file = tokens_file(cell);
  auto tokens = viewer::read_tokens(file);
  nlohmann::json out;
  if (!revoke.empty()) {
    const auto before = tokens.size();
    tokens.erase(std::remove_if(tokens.begin(), tokens.end(), [&](const auto& e) { return e.name == revoke; }),
                 tokens.end());
    out = {{"revoked", revoke}, {"tokens_removed", before - tokens.size()}};
  } else {
    if (person.empty()) throw CredentialsError("give --person NAME (whose token it is) or --revoke NAME");
    if (!valid_host(person)) throw CredentialsError("name '" + person + "': letters, digits, '-', '_' and '.' only (1-64)");
    const int days = days_wanted > 0 ? days_wanted : 30;
    const auto now = std::chrono::system_clock::now();
    const std::string token = viewer::new_token();
    viewer::TokenEntry e{viewer::sha256_hex(token),
                         std::chrono::duration_cast<std::chrono::seconds>(now.time_since_epoch()).count() + days * 86400LL,
                         person};
    tokens.push_back(e);
    out = {{"person", person}, {"token", token}, {"expires_unix", e.expires_unix},
           {"expires", utc(now + std::chrono::hours(24) * days) + "Z"}};
  }
  std::string text = "# skelgraph viewer tokens: sha256 of the token, expiry (unix seconds), name (skelgraph security token)\n";
  for (const auto& e : tokens) text += viewer::token_line(e) + "\n";
  write_file(fs::path(file + ".new"), text, fs::perms::owner_read | fs::perms::owner_write);
  fs::rename(file + ".new", file);  // the viewer reads the whole file or the old one, never half
  return out;
}

}  // namespace skelgraph::runtime::security
