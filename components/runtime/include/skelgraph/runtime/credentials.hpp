#pragma once
// A cell's DDS Security credentials and the viewer's, made and checked with
// the openssl program (`skelgraph security`, docs/security.md): a CA, a
// certificate per host, governance and permissions signed by the CA
// (security_policy.hpp says what each role may publish); the viewer's server
// certificate, people's client certificates and tokens. Each function returns
// what `--json` prints.

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "skelgraph/runtime/security_policy.hpp"

namespace skelgraph::runtime::security {

// What the user asked cannot be done (a bad host name, a CA already there):
// the message says what to do instead.
class CredentialsError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct CellSpec {
  std::string master;
  std::vector<std::string> sensors, readers, robots, robot_control;
  int days = 3650;     // validity of certificates and permissions
  bool force = false;  // replace credentials already in the directory
};

// The hosts and their roles (a host may hold several, but a reader no other).
// Throws CredentialsError for a bad or repeated name.
Hosts hosts_of(const CellSpec& spec);

// Makes DIR/ca.pem, ca.key, hosts/<host>.pem/.key, governance and permissions
// (.xml and the signed .p7s) and roles.json. Returns {"directory", "hosts":
// {host: {role, roles, publishes, denied}}}. Throws CredentialsError (a CA
// already there without force), std::runtime_error (openssl failed, saying how).
nlohmann::json make_cell_credentials(const std::string& dir, const CellSpec& spec);

// Checks the files, signatures, the CA's key usage, and each host's (or
// `host`'s) certificate, grant and roles. Returns {"directory", "ok",
// "checks": [{check, ok, detail}], "hosts": {host: {roles, publishes, denied, robot_commands}}}.
nlohmann::json check_cell_credentials(const std::string& dir, const std::string& host = "");

struct ViewerCertSpec {
  std::string server;                  // the viewer's host: a server certificate...
  std::string person;                  // ...or a person's client certificate (one of the two)
  std::vector<std::string> addresses;  // server: IP addresses and names browsers use
  int days = 0;                        // 0: 825 for a server, 90 for a person
};

// Returns {"kind", "name", "days", "certificate", "key", "addresses" (server)
// or "pkcs12" (person)}. Throws CredentialsError (no CA, a bad name, a server
// without addresses).
nlohmann::json make_viewer_certificate(const std::string& dir, const ViewerCertSpec& spec);

// A viewer token for `person` valid `days` (0: 30), printed once, its hash kept
// in DIR/viewer/tokens: {"person", "token", "expires_unix", "expires"}; or
// with `revoke`, every token of that name removed: {"revoked", "tokens_removed"}.
nlohmann::json viewer_token(const std::string& dir, const std::string& person, const std::string& revoke, int days = 0);

// A server certificate's subjectAltName for `addresses` ("IP:10.0.0.5,DNS:cell-pc").
std::string subject_alt_names(const std::vector<std::string>& addresses);

// The tokens file viewer_token writes.
std::string tokens_file(const std::string& dir);

}  // namespace skelgraph::runtime::security
