// skelgraph security init|check|viewer|token: DDS Security credentials for a
// cell (a CA, a certificate per host, signed governance and permissions) and
// the viewer's (a server certificate, people's certificates, tokens), made and
// checked with the openssl program (runtime/credentials.hpp). See docs/security.md.

#include <cstdio>
#include <filesystem>
#include <memory>

#include <nlohmann/json.hpp>

#include "cli.hpp"
#include "skelgraph/runtime/credentials.hpp"

namespace skelgraph::cli {

namespace {

using namespace runtime::security;

std::string joined(const std::vector<std::string>& v, const char* sep = "+") {
  std::string out;
  for (const auto& s : v) out += (out.empty() ? "" : sep) + s;
  return out;
}

struct InitOpts : CellSpec {
  std::string dir;
  bool json = false;
  std::string host;  // check: one host (default: every host in hosts/)
};

int init(const InitOpts& o) {
  const auto hosts = user_input<CredentialsError>([&] { return hosts_of(o); });
  const auto out = user_input<CredentialsError>([&] { return make_cell_credentials(o.dir, o); });
  const std::string dir = out["directory"];
  if (o.json) {
    std::printf("%s\n", out.dump().c_str());
  } else {
    std::printf("cell credentials in %s\n", dir.c_str());
    for (const auto& [h, roles] : hosts) std::printf("  %-20s %s\n", h.c_str(), joined(roles).c_str());
    std::printf("give each host ca.pem, governance.p7s, permissions.p7s and its hosts/<host>.pem/.key; keep ca.key "
                "off the hosts.\nrun: skelgraph launch FILE --host HOST --profile secure --security DIR\n");
  }
  return 0;
}

int check(const InitOpts& o) {
  const auto out = check_cell_credentials(o.dir, o.host);
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

struct ViewerOpts : ViewerCertSpec {
  std::string dir, revoke;
  bool json = false;
};

// `security viewer`: the viewer's server certificate (--server) or a person's client certificate (--person).
int viewer_cert(const ViewerOpts& o) {
  const auto out = user_input<CredentialsError>([&] { return make_viewer_certificate(o.dir, o); });
  const bool server = !o.server.empty();
  const std::string name = out["name"], dir = std::filesystem::absolute(o.dir).string();
  const int days = out["days"];
  const std::string san = subject_alt_names(o.addresses);
  if (o.json) {
    std::printf("%s\n", out.dump().c_str());
  } else if (server) {
    std::printf("viewer server certificate for %s (%s), %d days: %s\nthe viewer on host %s uses it when it is given "
                "credentials: %s; browsers trust the cell's CA (%s/ca.pem)\n",
                name.c_str(), san.c_str(), days, out["certificate"].get<std::string>().c_str(), name.c_str(),
                dir.c_str(), dir.c_str());
  } else {
    std::printf("viewer certificate for %s, %d days: %s (with its key and the CA: %s, no password: import it into the "
                "browser)\n",
                name.c_str(), days, out["certificate"].get<std::string>().c_str(), out["pkcs12"].get<std::string>().c_str());
  }
  return 0;
}

// `security token`: a viewer token for a person (printed once; only its hash is kept), or --revoke NAME.
int viewer_token(const ViewerOpts& o) {
  const auto out = user_input<CredentialsError>([&] { return runtime::security::viewer_token(o.dir, o.person, o.revoke, o.days); });
  const std::string file = tokens_file(o.dir);
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
