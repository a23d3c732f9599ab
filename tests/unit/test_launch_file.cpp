#include <gtest/gtest.h>

#include <fstream>

#include "skelgraph/runtime/launch_file.hpp"

using namespace skelgraph::runtime;

namespace {

// A registry with schema-only entries: resolving needs no component instances.
ComponentRegistry registry() {
  ComponentRegistry r;
  ComponentInfo sync{"sync_master", "test", {}};
  sync.params.add_double("tick_period_ms", 33.0, "", 1.0, 10000.0).add_string("label", "session", "");
  r.add(sync, nullptr);
  ComponentInfo sim{"sim", "test", {}};
  sim.params.add_int("sensors", 2, "", 1, 8);
  r.add(sim, nullptr);
  return r;
}

std::string error_of(const std::string& text, const std::string& host = "") {
  try {
    resolve_launch(parse_launch_text(text, "cell.yaml"), registry(), host);
  } catch (const LaunchError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(LaunchFile, ParsesComponentsHostsAndParams) {
  const auto spec = parse_launch_text(R"(
profile: lan
domain: 7
components:
  - name: sync
    type: sync_master
    host: fusion
    params:
      tick_period_ms: 20
      label: walk
  - name: sim_a
    type: sim
    host: [sensor1, sensor2]
)",
                                      "cell.yaml");
  EXPECT_EQ(spec.profile.value(), "lan");
  EXPECT_EQ(spec.domain.value(), 7);
  ASSERT_EQ(spec.components.size(), 2u);
  EXPECT_EQ(spec.components[0].origin, "cell.yaml:5:5");
  EXPECT_EQ(spec.components[1].hosts, (std::vector<std::string>{"sensor1", "sensor2"}));
  EXPECT_EQ(spec.components[0].params[0].origin, "cell.yaml:9:7");

  const auto all = resolve_launch(spec, registry(), "");
  ASSERT_EQ(all.size(), 2u);
  EXPECT_DOUBLE_EQ(all[0].params.get<double>("tick_period_ms"), 20.0);
  EXPECT_EQ(all[0].params.get<std::string>("label"), "walk");
  EXPECT_EQ(all[1].params.get<std::int64_t>("sensors"), 2);

  const auto fusion = resolve_launch(spec, registry(), "fusion");
  ASSERT_EQ(fusion.size(), 1u);
  EXPECT_EQ(fusion[0].name, "sync");
  EXPECT_EQ(resolve_launch(spec, registry(), "sensor2").at(0).name, "sim_a");
}

TEST(LaunchFile, FileOnDisk) {
  const std::string path = ::testing::TempDir() + "/good.yaml";
  std::ofstream(path) << "components:\n  - {name: s, type: sync_master}\n";
  const auto spec = parse_launch_file(path);
  EXPECT_EQ(spec.source, path);
  EXPECT_EQ(resolve_launch(spec, registry(), "").size(), 1u);
  try {
    parse_launch_file(::testing::TempDir() + "/missing.yaml");
    FAIL();
  } catch (const LaunchError& e) {
    EXPECT_NE(std::string(e.what()).find("missing.yaml: cannot open"), std::string::npos);
  }
}

TEST(LaunchFile, BadFilesGiveLineAndReason) {
  EXPECT_NE(error_of("components: [\n").find("cell.yaml:2:1: not valid YAML"), std::string::npos)
      << error_of("components: [\n");
  EXPECT_NE(error_of("- a\n- b\n").find("expected a mapping"), std::string::npos);
  EXPECT_NE(error_of("components: []\n").find("no components"), std::string::npos);
  EXPECT_NE(error_of("compnents:\n  - {name: a, type: sim}\n").find("cell.yaml:1:1: unknown key 'compnents'"),
            std::string::npos);
  EXPECT_NE(error_of("components:\n  - {name: a}\n").find("has no 'type'"), std::string::npos);
  EXPECT_NE(error_of("components:\n  - {type: sim}\n").find("without a 'name'"), std::string::npos);
  EXPECT_NE(error_of("components:\n  - {name: a, type: sim, colour: red}\n").find("unknown key 'colour'"),
            std::string::npos);
  EXPECT_NE(error_of("components:\n  - {name: a, type: sim}\n  - {name: a, type: sim}\n").find("used twice"),
            std::string::npos);
  EXPECT_NE(error_of("domain: 300\ncomponents:\n  - {name: a, type: sim}\n").find("cell.yaml:1:9: 'domain'"),
            std::string::npos);
  EXPECT_NE(error_of("components:\n  - {name: a, type: sim, params: [1, 2]}\n").find("'params' expects a mapping"),
            std::string::npos);
}

TEST(LaunchFile, UnknownTypeAndBadParamsNameFileLineAndKey) {
  const auto unknown = error_of("components:\n  - name: a\n    type: fusion\n");
  EXPECT_NE(unknown.find("cell.yaml:2:5: component 'a' has unknown type 'fusion' (known: sim, sync_master)"),
            std::string::npos)
      << unknown;
  const auto bad = error_of("components:\n  - name: sync\n    type: sync_master\n    params:\n      tick_perod_ms: 5\n");
  EXPECT_NE(bad.find("cell.yaml:5:7: component 'sync' (sync_master): unknown parameter 'tick_perod_ms'"),
            std::string::npos)
      << bad;
  const auto wrong = error_of("components:\n  - name: s\n    type: sim\n    params: {sensors: many}\n");
  EXPECT_NE(wrong.find("parameter 'sensors' expects integer"), std::string::npos) << wrong;
}

TEST(LaunchFile, HostWithoutComponentsIsAnError) {
  const auto e = error_of("components:\n  - {name: a, type: sim, host: h1}\n", "h9");
  EXPECT_NE(e.find("no components for host 'h9' (hosts named there: h1)"), std::string::npos) << e;
}

// skelgraph launch FILE --set COMPONENT.KEY=VALUE: over the file's values,
// checked like them; a bad one says which and why.
TEST(LaunchFile, CommandLineSetsParamsOverTheFile) {
  auto spec = parse_launch_text("components:\n  - name: sync\n    type: sync_master\n    params: {label: walk}\n"
                                "  - name: sim_a\n    type: sim\n",
                                "cell.yaml");
  set_launch_params(spec, {"sync.label=shift", "sim_a.sensors=4", "sync.tick_period_ms=20"});
  const auto all = resolve_launch(spec, registry(), "");
  EXPECT_EQ(all[0].params.get<std::string>("label"), "shift");
  EXPECT_DOUBLE_EQ(all[0].params.get<double>("tick_period_ms"), 20.0);
  EXPECT_EQ(all[1].params.get<std::int64_t>("sensors"), 4);
  const auto error = [&](const std::string& a) {
    auto s = spec;
    try {
      set_launch_params(s, {a});
      resolve_launch(s, registry(), "");
    } catch (const LaunchError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_NE(error("fusion.method=avg").find("--set fusion.method=avg: cell.yaml has no component 'fusion' (it has: sync, sim_a)"),
            std::string::npos);
  EXPECT_NE(error("sim_a=4").find("expected COMPONENT.KEY=VALUE"), std::string::npos);
  EXPECT_NE(error("sim_a.sensors=99").find("--set sim_a.sensors=99"), std::string::npos) << error("sim_a.sensors=99");
}
