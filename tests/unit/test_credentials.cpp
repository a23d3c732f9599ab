// A cell's credentials made and checked with openssl: a made cell checks
// right, a tampered signature and a host without a grant do not; host names
// and roles are checked before anything is made; the viewer's certificates
// and tokens (added, then revoked).
#include <gtest/gtest.h>

#include "../support/temp_dir.hpp"

#include <filesystem>
#include <fstream>

#include "skelgraph/runtime/credentials.hpp"

using namespace skelgraph::runtime::security;
namespace fs = std::filesystem;

namespace {
bool check_passed(const nlohmann::json& out, const std::string& what) {
  for (const auto& c : out["checks"]) {
    if (c["check"].get<std::string>().find(what) != std::string::npos) return c["ok"].get<bool>();
  }
  ADD_FAILURE() << "no check '" << what << "' in " << out["checks"];
  return false;
}
}  // namespace

TEST(Credentials, HostsAndRolesAreCheckedFirst) {
  CellSpec spec;
  spec.master = "fusion-pc";
  spec.sensors = {"cam-1", "cam-2"};
  spec.robot_control = {"fusion-pc"};
  const auto hosts = hosts_of(spec);
  ASSERT_EQ(hosts.size(), 3u);
  EXPECT_EQ(hosts[0].second, (std::vector<std::string>{"master", "robot-control"}));
  spec.sensors = {"cam 1"};
  EXPECT_THROW(hosts_of(spec), CredentialsError);
  spec.sensors = {"cam-1", "cam-1"};
  EXPECT_THROW(hosts_of(spec), CredentialsError);
  spec.sensors = {};
  spec.readers = {"fusion-pc"};  // a reader has no other role
  EXPECT_THROW(hosts_of(spec), CredentialsError);
}

TEST(Credentials, AMadeCellChecksRightAndATamperedOneDoesNot) {
  const auto dir = skelgraph::test::fresh_path("cell_credentials").string();
  CellSpec spec;
  spec.master = "fusion-pc";
  spec.sensors = {"cam-1"};
  spec.robot_control = {"fusion-pc"};
  spec.days = 30;
  const auto made = make_cell_credentials(dir, spec);
  EXPECT_EQ(made["hosts"]["cam-1"]["role"], "sensor");
  EXPECT_TRUE(fs::exists(fs::path(dir) / "hosts" / "cam-1.pem"));
  EXPECT_THROW(make_cell_credentials(dir, spec), CredentialsError);  // a CA is there: not replaced without force
  const auto ok = check_cell_credentials(dir);
  EXPECT_TRUE(ok["ok"].get<bool>()) << ok["checks"];
  EXPECT_EQ(ok["hosts"].size(), 2u);
  EXPECT_FALSE(ok["hosts"]["cam-1"]["robot_commands"].get<bool>());
  EXPECT_TRUE(ok["hosts"]["fusion-pc"]["robot_commands"].get<bool>());
  // The signed permissions changed after signing (a grant widened): the signature no longer verifies.
  {
    const auto path = fs::path(dir) / "permissions.p7s";
    std::ifstream in(path);
    std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    const auto at = text.find("<topic>skelgraph/skeleton/raw</topic>");
    ASSERT_NE(at, std::string::npos);
    text.replace(at, 37, "<topic>*</topic>");
    std::ofstream(path) << text;
  }
  const auto bad = check_cell_credentials(dir, "cam-1");
  EXPECT_FALSE(bad["ok"].get<bool>());
  EXPECT_FALSE(check_passed(bad, "permissions.p7s signed by ca.pem"));
  EXPECT_TRUE(check_passed(bad, "governance.p7s signed by ca.pem"));
  // A host with a certificate the CA did not sign and no grant.
  fs::copy_file(fs::path(dir) / "hosts" / "cam-1.pem", fs::path(dir) / "hosts" / "stranger.pem");
  fs::copy_file(fs::path(dir) / "hosts" / "cam-1.key", fs::path(dir) / "hosts" / "stranger.key");
  EXPECT_FALSE(check_passed(check_cell_credentials(dir, "stranger"), "host stranger: granted in permissions.xml"));
}

TEST(Credentials, TheViewersCertificatesAndTokens) {
  const auto dir = skelgraph::test::fresh_path("viewer_credentials").string();
  ViewerCertSpec server;
  server.server = "fusion-pc";
  EXPECT_THROW(make_viewer_certificate(dir, server), CredentialsError);  // no cell CA yet
  CellSpec spec;
  spec.master = "fusion-pc";
  make_cell_credentials(dir, spec);
  EXPECT_THROW(make_viewer_certificate(dir, server), CredentialsError);  // a server needs its addresses
  server.addresses = {"10.0.0.5", "cell-pc"};
  EXPECT_EQ(subject_alt_names(server.addresses), "IP:10.0.0.5,DNS:cell-pc");
  const auto s = make_viewer_certificate(dir, server);
  EXPECT_EQ(s["kind"], "server");
  EXPECT_EQ(s["days"], 825);
  EXPECT_TRUE(fs::exists(s["certificate"].get<std::string>()));
  ViewerCertSpec person;
  person.person = "ann";
  const auto p = make_viewer_certificate(dir, person);
  EXPECT_EQ(p["days"], 90);
  EXPECT_TRUE(fs::exists(p["pkcs12"].get<std::string>()));

  const auto t1 = viewer_token(dir, "ann", "", 7);
  const auto t2 = viewer_token(dir, "bob", "");
  EXPECT_EQ(t1["token"].get<std::string>().size(), t2["token"].get<std::string>().size());
  EXPECT_NE(t1["token"], t2["token"]);
  std::ifstream in(tokens_file(dir));
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_EQ(text.find(t1["token"].get<std::string>()), std::string::npos);  // only its hash is kept
  const auto r = viewer_token(dir, "", "ann");
  EXPECT_EQ(r["tokens_removed"], 1);
  EXPECT_THROW(viewer_token(dir, "", ""), CredentialsError);
}
