// skelgraph security init|check: DDS Security credentials for a cell (a CA,
// a certificate per host, signed governance and permissions), made and
// checked with the openssl program. See docs/security.md.

#include <fcntl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

#include <nlohmann/json.hpp>

#include "cli.hpp"
#include "skelgraph/runtime/topics.hpp"

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

// What each role may publish (every role may subscribe to everything).
std::vector<std::string> publishes(const std::string& role) {
  namespace t = runtime::topics;
  if (role == "master") return {"*"};
  if (role == "sensor") {
    return {t::kSkeletonRaw.name, t::kSkeletonTruth.name, t::kSensorFrame.name, t::kCalibration.name,
            t::kDepth.name,       t::kCloud.name,         t::kSyncAck.name,     t::kStatus.name,
            t::kPlayState.name};
  }
  return {t::kSyncAck.name, t::kStatus.name};  // reader
}

const char* kDomains = "<domains><id_range><min>0</min><max>232</max></id_range></domains>";

std::string governance_xml() {
  return std::string(R"(<?xml version="1.0" encoding="UTF-8"?>
<!-- skelgraph cell governance (skelgraph security init): only authenticated
     participants join; discovery, liveliness and all RTPS traffic encrypted;
     every topic under read and write access control. -->
<dds xmlns:xsi="http://www.w3.org/2001/XMLSchema-instance" xsi:noNamespaceSchemaLocation="http://www.omg.org/spec/DDS-SECURITY/20170901/omg_shared_ca_governance.xsd">
  <domain_access_rules>
    <domain_rule>
      )") + kDomains + R"(
      <allow_unauthenticated_participants>false</allow_unauthenticated_participants>
      <enable_join_access_control>true</enable_join_access_control>
      <discovery_protection_kind>ENCRYPT</discovery_protection_kind>
      <liveliness_protection_kind>ENCRYPT</liveliness_protection_kind>
      <rtps_protection_kind>ENCRYPT</rtps_protection_kind>
      <topic_access_rules>
        <topic_rule>
          <topic_expression>*</topic_expression>
          <enable_discovery_protection>true</enable_discovery_protection>
          <enable_liveliness_protection>true</enable_liveliness_protection>
          <enable_read_access_control>true</enable_read_access_control>
          <enable_write_access_control>true</enable_write_access_control>
          <metadata_protection_kind>ENCRYPT</metadata_protection_kind>
          <data_protection_kind>ENCRYPT</data_protection_kind>
        </topic_rule>
      </topic_access_rules>
    </domain_rule>
  </domain_access_rules>
</dds>
)";
}

std::string permissions_xml(const std::vector<std::pair<std::string, std::string>>& hosts, const std::string& from,
                            const std::string& until) {
  std::ostringstream x;
  x << R"(<?xml version="1.0" encoding="UTF-8"?>
<!-- skelgraph cell permissions (skelgraph security init): the sync master host
     may publish everything; sensor hosts their sensors' topics; reader hosts
     only acks and status. Every host may subscribe to everything. -->
<dds xmlns:xsi="http://www.w3.org/2001/XMLSchema-instance" xsi:noNamespaceSchemaLocation="http://www.omg.org/spec/DDS-SECURITY/20170901/omg_shared_ca_permissions.xsd">
  <permissions>
)";
  for (const auto& [host, role] : hosts) {
    x << "    <grant name=\"" << host << "\">\n"
      << "      <subject_name>CN=" << host << "</subject_name>\n"
      << "      <validity><not_before>" << from << "</not_before><not_after>" << until << "</not_after></validity>\n"
      << "      <allow_rule>\n        " << kDomains << "\n        <publish><topics>";
    for (const auto& t : publishes(role)) x << "<topic>" << t << "</topic>";
    x << "</topics></publish>\n        <subscribe><topics><topic>*</topic></topics></subscribe>\n"
      << "      </allow_rule>\n      <default>DENY</default>\n    </grant>\n";
  }
  x << "  </permissions>\n</dds>\n";
  return x.str();
}

bool valid_host(const std::string& h) {
  return !h.empty() && h.size() <= 64 && h.find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789-_.") == std::string::npos;
}

struct InitOpts {
  std::string dir;
  std::string master;
  std::vector<std::string> sensors, readers;
  int days = 3650;
  bool force = false;
  bool json = false;
  std::string host;  // check: one host (default: every host in hosts/)
};

int init(const InitOpts& o) {
  std::vector<std::pair<std::string, std::string>> hosts{{o.master, "master"}};
  for (const auto& h : o.sensors) hosts.emplace_back(h, "sensor");
  for (const auto& h : o.readers) hosts.emplace_back(h, "reader");
  std::set<std::string> seen;
  for (const auto& [h, role] : hosts) {
    if (!valid_host(h)) throw UsageError("host name '" + h + "': letters, digits, '-', '_' and '.' only (1-64)");
    if (!seen.insert(h).second) throw UsageError("host '" + h + "' named twice");
  }
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
  for (const auto& [h, role] : hosts) {
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
  for (const auto& [h, role] : hosts) out["hosts"][h] = {{"role", role}, {"publishes", publishes(role)}};
  if (o.json) {
    std::printf("%s\n", out.dump().c_str());
  } else {
    std::printf("cell credentials in %s\n", dir.string().c_str());
    for (const auto& [h, role] : hosts) std::printf("  %-20s %s\n", h.c_str(), role.c_str());
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
  for (const auto& h : hosts) {
    if (!fs::is_regular_file(dir / "hosts" / (h + ".pem")) || !fs::is_regular_file(dir / "hosts" / (h + ".key"))) {
      record("host " + h, false, "no hosts/" + h + ".pem and .key");
      continue;
    }
    attempt("host " + h + ": certificate signed by ca.pem", {"verify", "-CAfile", "ca.pem", "hosts/" + h + ".pem"});
    record("host " + h + ": granted in permissions.xml",
           permissions.find("<subject_name>CN=" + h + "</subject_name>") != std::string::npos,
           "a grant for subject CN=" + h);
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
  in->add_option("--days", o->days, "validity of certificates and permissions")->check(CLI::Range(1, 36500));
  in->add_flag("--force", o->force, "replace the credentials already in DIR");
  in->add_flag("--json", o->json, "print the hosts and what each may publish as JSON");
  in->callback([o, &run] { run = [o] { return init(*o); }; });
  auto* ch = cmd->add_subcommand("check", "Check credentials: signatures, the CA's key usage, each host's certificate and grant");
  ch->add_option("DIR", o->dir, "the credentials directory")->required()->check(CLI::ExistingDirectory);
  ch->add_option("--host", o->host, "check only this host (default: every host in DIR/hosts)");
  ch->add_flag("--json", o->json, "the checks as JSON");
  ch->callback([o, &run] { run = [o] { return check(*o); }; });
}

}  // namespace skelgraph::cli
