// skelgraph security init|check|viewer|token: DDS Security credentials for a
// cell (a CA, a certificate per host, signed governance and permissions) and
// the viewer's (a server certificate, people's certificates, tokens), made and
// checked with the openssl program. See docs/security.md.

#include <fcntl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

#include <nlohmann/json.hpp>

#include "cli.hpp"
#include "skelgraph/runtime/security_policy.hpp"
#include "skelgraph/runtime/topics.hpp"
#include "skelgraph/viewer/access.hpp"

namespace skelgraph::cli {

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


using namespace runtime::security;

struct InitOpts {
  std::string dir;
  std::string master;
  std::vector<std::string> sensors, readers, robots, robot_control;
  int days = 3650;
  bool force = false;
  bool json = false;
  std::string host;  // check: one host (default: every host in hosts/)
};

int init(const InitOpts& o) {
  // A host may hold several roles (the fusion host as master and robot-control).
  Hosts hosts;
  const auto add = [&](const std::string& h, const std::string& role) {
    if (!valid_host(h)) throw UsageError("host name '" + h + "': letters, digits, '-', '_' and '.' only (1-64)");
    for (auto& [name, roles] : hosts) {
      if (name != h) continue;
      if (std::find(roles.begin(), roles.end(), role) != roles.end()) throw UsageError("host '" + h + "' named twice as " + role);
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
      throw UsageError("host '" + h + "' is a reader and " + joined(roles, ", ") + ": a reader has no other role");
  const fs::path dir = fs::absolute(o.dir);
  if (fs::exists(dir / "ca.key") && !o.force) {
    throw UsageError(dir.string() + " already holds a CA (ca.key): use --force to make a new cell (every host then "
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
  if (o.json) {
    std::printf("%s\n", out.dump().c_str());
  } else {
    std::printf("cell credentials in %s\n", dir.string().c_str());
    for (const auto& [h, roles] : hosts) std::printf("  %-20s %s\n", h.c_str(), joined(roles).c_str());
    std::printf("give each host ca.pem, governance.p7s, permissions.p7s and its hosts/<host>.pem/.key; keep ca.key "
                "off the hosts.\nrun: skelgraph launch FILE --host HOST --profile secure --security DIR\n");
  }
  return 0;
}

int check(const InitOpts& o) {
  const fs::path dir = fs::absolute(o.dir);
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
  if (!o.host.empty()) {
    hosts.push_back(o.host);
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
  if (o.json) {
    std::printf("%s\n", out.dump().c_str());
  } else {
    for (const auto& c : out["checks"]) {
      std::printf("%s  %s%s\n", c["ok"].get<bool>() ? "ok  " : "FAIL", c["check"].get<std::string>().c_str(),
                  c["ok"].get<bool>() ? "" : (": " + c["detail"].get<std::string>()).c_str());
    }
    std::printf("%s\n", out["ok"].get<bool>() ? "credentials look right" : "credentials have problems (above)");
  }
  return out["ok"].get<bool>() ? 0 : 1;
}

struct ViewerOpts {
  std::string dir, server, person, revoke;
  std::vector<std::string> addresses;
  int days = 0;  // 0: the kind's default
  bool json = false;
};

fs::path cell_dir(const std::string& d) {
  const fs::path dir = fs::absolute(d);
  if (!fs::is_regular_file(dir / "ca.pem") || !fs::is_regular_file(dir / "ca.key"))
    throw UsageError(dir.string() + " holds no cell CA (ca.pem and ca.key): make one with skelgraph security init");
  fs::create_directories(dir / "viewer" / "people");
  fs::permissions(dir / "viewer", fs::perms::owner_all, fs::perm_options::replace);
  return dir;
}

// `security viewer`: the viewer's server certificate (--server) or a person's client certificate (--person).
int viewer_cert(const ViewerOpts& o) {
  if (o.server.empty() == o.person.empty()) throw UsageError("give either --server HOST or --person NAME");
  const bool server = !o.server.empty();
  const std::string name = server ? o.server : o.person;
  if (!valid_host(name)) throw UsageError("name '" + name + "': letters, digits, '-', '_' and '.' only (1-64)");
  if (server && o.addresses.empty())
    throw UsageError("--server needs --address: the IP addresses and names browsers will use to reach the viewer");
  const fs::path dir = cell_dir(o.dir);
  const int days = o.days > 0 ? o.days : server ? 825 : 90;
  std::string san;
  for (const auto& a : o.addresses) {
    bool ip = false;
    try {
      viewer::is_loopback_address(a);
      ip = true;
    } catch (const std::exception&) {
      if (!valid_host(a)) throw UsageError("--address '" + a + "': an IP address or a host name");
    }
    san += (san.empty() ? "" : ",") + std::string(ip ? "IP:" : "DNS:") + a;
  }
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
  if (o.json) {
    std::printf("%s\n", out.dump().c_str());
  } else if (server) {
    std::printf("viewer server certificate for %s (%s), %d days: %s\nthe viewer on host %s uses it when it is given "
                "credentials: %s; browsers trust the cell's CA (%s/ca.pem)\n",
                name.c_str(), san.c_str(), days, out["certificate"].get<std::string>().c_str(), name.c_str(),
                dir.string().c_str(), dir.string().c_str());
  } else {
    std::printf("viewer certificate for %s, %d days: %s (with its key and the CA: %s, no password: import it into the "
                "browser)\n",
                name.c_str(), days, out["certificate"].get<std::string>().c_str(), out["pkcs12"].get<std::string>().c_str());
  }
  return 0;
}

// `security token`: a viewer token for a person (printed once; only its hash is kept), or --revoke NAME.
int viewer_token(const ViewerOpts& o) {
  const fs::path dir = cell_dir(o.dir);
  const std::string file = (dir / "viewer" / "tokens").string();
  auto tokens = viewer::read_tokens(file);
  nlohmann::json out;
  if (!o.revoke.empty()) {
    const auto before = tokens.size();
    tokens.erase(std::remove_if(tokens.begin(), tokens.end(), [&](const auto& e) { return e.name == o.revoke; }),
                 tokens.end());
    out = {{"revoked", o.revoke}, {"tokens_removed", before - tokens.size()}};
  } else {
    if (o.person.empty()) throw UsageError("give --person NAME (whose token it is) or --revoke NAME");
    if (!valid_host(o.person)) throw UsageError("name '" + o.person + "': letters, digits, '-', '_' and '.' only (1-64)");
    const int days = o.days > 0 ? o.days : 30;
    const auto now = std::chrono::system_clock::now();
    const std::string token = viewer::new_token();
    viewer::TokenEntry e{viewer::sha256_hex(token),
                         std::chrono::duration_cast<std::chrono::seconds>(now.time_since_epoch()).count() + days * 86400LL,
                         o.person};
    tokens.push_back(e);
    out = {{"person", o.person}, {"token", token}, {"expires_unix", e.expires_unix},
           {"expires", utc(now + std::chrono::hours(24) * days) + "Z"}};
  }
  std::string text = "# skelgraph viewer tokens: sha256 of the token, expiry (unix seconds), name (skelgraph security token)\n";
  for (const auto& e : tokens) text += viewer::token_line(e) + "\n";
  write_file(fs::path(file + ".new"), text, fs::perms::owner_read | fs::perms::owner_write);
  fs::rename(file + ".new", file);  // the viewer reads the whole file or the old one, never half
  if (o.json) {
    std::printf("%s\n", out.dump().c_str());
  } else if (!o.revoke.empty()) {
    std::printf("removed %zu token(s) of %s from %s\n", out["tokens_removed"].get<std::size_t>(), o.revoke.c_str(), file.c_str());
  } else {
    std::printf("token for %s, valid until %s (shown only now; %s keeps its hash):\n%s\nopen "
                "https://VIEWER:PORT/?token=%s\n",
                o.person.c_str(), out["expires"].get<std::string>().c_str(), file.c_str(),
                out["token"].get<std::string>().c_str(), out["token"].get<std::string>().c_str());
  }
  return 0;
}

}  // namespace

void add_security_command(CLI::App& app, GlobalOptions&, Action& run) {
  auto o = std::make_shared<InitOpts>();
  auto* cmd = app.add_subcommand("security", "DDS Security credentials for a cell (the secure profile)");
  cmd->require_subcommand(1);
  auto* in = cmd->add_subcommand(
      "init", "Make a CA, a certificate per host, and signed governance and permissions (with openssl)");
  in->add_option("DIR", o->dir, "directory for the credentials (created)")->required();
  in->add_option("--master", o->master, "the sync master's host: may publish every topic")->required();
  in->add_option("--sensors", o->sensors, "sensor hosts: may publish raw skeletons, truth, depth, poses, acks, status")
      ->delimiter(',');
  in->add_option("--readers", o->readers, "hosts that may only read (and publish acks and status)")->delimiter(',');
  in->add_option("--robots", o->robots, "robot hosts: may publish skelgraph/robot/state (and acks, status)")->delimiter(',');
  in->add_option("--robot-control", o->robot_control,
                 "hosts that run follow/separation/fetch: the only ones that may publish skelgraph/robot/command and "
                 "skelgraph/safety (may also be the master)")
      ->delimiter(',');
  in->add_option("--days", o->days, "validity of certificates and permissions")->check(CLI::Range(1, 36500));
  in->add_flag("--force", o->force, "replace the credentials already in DIR");
  in->add_flag("--json", o->json, "print the hosts and what each may publish as JSON");
  in->callback([o, &run] { run = [o] { return init(*o); }; });
  auto* ch = cmd->add_subcommand("check", "Check credentials: signatures, the CA's key usage, each host's certificate and grant");
  ch->add_option("DIR", o->dir, "the credentials directory")->required()->check(CLI::ExistingDirectory);
  ch->add_option("--host", o->host, "check only this host (default: every host in DIR/hosts)");
  ch->add_flag("--json", o->json, "the checks as JSON");
  ch->callback([o, &run] { run = [o] { return check(*o); }; });

  auto v = std::make_shared<ViewerOpts>();
  auto* vw = cmd->add_subcommand("viewer",
                                 "Certificates for the browser viewer: its server certificate (--server), or a person's "
                                 "client certificate (--person, OU=viewer, with a .p12 for the browser)");
  vw->add_option("DIR", v->dir, "the cell's credentials directory (skelgraph security init)")->required();
  vw->add_option("--server", v->server, "the viewer's host (its --host name): a server certificate");
  vw->add_option("--address", v->addresses, "with --server: IP addresses and names browsers use to reach it")->delimiter(',');
  vw->add_option("--person", v->person, "a person who may look: a client certificate");
  vw->add_option("--days", v->days, "validity (default: 825 for a server, 90 for a person)")->check(CLI::Range(1, 3650));
  vw->add_flag("--json", v->json, "what was made, as JSON");
  vw->callback([v, &run] { run = [v] { return viewer_cert(*v); }; });
  auto* tk = cmd->add_subcommand("token", "A viewer token for a person (printed once), or --revoke NAME");
  tk->add_option("DIR", v->dir, "the cell's credentials directory (skelgraph security init)")->required();
  tk->add_option("--person", v->person, "whose token it is");
  tk->add_option("--days", v->days, "validity (default 30)")->check(CLI::Range(1, 3650));
  tk->add_option("--revoke", v->revoke, "remove every token of this person");
  tk->add_flag("--json", v->json, "the token and its expiry as JSON");
  tk->callback([v, &run] { run = [v] { return viewer_token(*v); }; });
}

}  // namespace skelgraph::cli
