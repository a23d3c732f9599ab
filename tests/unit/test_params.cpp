#include <gtest/gtest.h>

#include "skelgraph/runtime/params.hpp"

using namespace skelgraph::runtime;

namespace {
ParamSchema schema() {
  ParamSchema s;
  s.add_double("period_ms", 33.0, "tick period", 1.0, 1000.0)
      .add_int("count", 3, "how many", 0, 10)
      .add_bool("enabled", true, "on/off")
      .add_string("mode", "avg", "fusion method", {"avg", "sum"})
      .add_string_list("topics", {"a"}, "topics")
      .add(ParamSpec{"sensor", ParamType::String, std::nullopt, "required sensor id", {}, {}, {}});
  return s;
}
RawParam raw(const std::string& k, const std::string& v) { return RawParam{k, v, "f.yaml:3:5"}; }
}  // namespace

TEST(Params, DefaultsFilledAndValuesConverted) {
  const auto p = schema().resolve({raw("sensor", "k1"), raw("period_ms", "20.5"), raw("count", "7"),
                                   raw("enabled", "false"), raw("mode", "sum"), raw("topics", "x,y")},
                                  "component 'c' (t)");
  EXPECT_DOUBLE_EQ(p.get<double>("period_ms"), 20.5);
  EXPECT_EQ(p.get<std::int64_t>("count"), 7);
  EXPECT_FALSE(p.get<bool>("enabled"));
  EXPECT_EQ(p.get<std::string>("mode"), "sum");
  EXPECT_EQ(p.get<std::vector<std::string>>("topics"), (std::vector<std::string>{"x", "y"}));
  const auto d = schema().resolve({raw("sensor", "k1")}, "c");
  EXPECT_DOUBLE_EQ(d.get<double>("period_ms"), 33.0);
  EXPECT_TRUE(d.get<bool>("enabled"));
}

TEST(Params, YamlListArrivesAsList) {
  RawParam r{"topics", std::vector<std::string>{"skelgraph/sync", "skelgraph/status"}, "f:1:1"};
  const auto p = schema().resolve({raw("sensor", "s"), r}, "c");
  EXPECT_EQ(p.get<std::vector<std::string>>("topics").size(), 2u);
}

TEST(Params, UnknownKeyIsAnErrorNamingOriginAndKnownKeys) {
  try {
    schema().resolve({raw("sensor", "s"), raw("perod_ms", "3")}, "component 'sync' (sync_master)");
    FAIL() << "expected ParamError";
  } catch (const ParamError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("f.yaml:3:5"), std::string::npos) << m;
    EXPECT_NE(m.find("component 'sync' (sync_master)"), std::string::npos) << m;
    EXPECT_NE(m.find("unknown parameter 'perod_ms'"), std::string::npos) << m;
    EXPECT_NE(m.find("period_ms"), std::string::npos) << m;
  }
}

TEST(Params, WrongTypesAndRangesAreErrors) {
  const auto s = schema();
  auto message = [&](std::vector<RawParam> r) {
    r.push_back(raw("sensor", "s"));
    try {
      s.resolve(r, "c");
    } catch (const ParamError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_NE(message({raw("period_ms", "fast")}).find("expects number"), std::string::npos);
  EXPECT_NE(message({raw("period_ms", "0.5")}).find("in [1, 1000]"), std::string::npos);
  EXPECT_NE(message({raw("count", "2.5")}).find("expects integer"), std::string::npos);
  EXPECT_NE(message({raw("count", "11")}).find("got 11"), std::string::npos);
  EXPECT_NE(message({raw("enabled", "maybe")}).find("expects bool"), std::string::npos);
  EXPECT_NE(message({raw("mode", "median")}).find("one of {avg, sum}"), std::string::npos);
  EXPECT_NE(message({raw("period_ms", "nan")}).find("expects number"), std::string::npos);
  RawParam list{"count", std::vector<std::string>{"1"}, "f:1:1"};
  EXPECT_NE(message({list}).find("got a list"), std::string::npos);
  EXPECT_NE(message({raw("count", "1"), raw("count", "2")}).find("given twice"), std::string::npos);
}

TEST(Params, MissingRequiredIsAnError) {
  try {
    schema().resolve({}, "component 'x' (y)");
    FAIL();
  } catch (const ParamError& e) {
    EXPECT_NE(std::string(e.what()).find("required parameter 'sensor'"), std::string::npos);
  }
}

TEST(Params, AllProblemsReportedAtOnce) {
  try {
    schema().resolve({raw("a", "1"), raw("b", "2"), raw("count", "x")}, "c");
    FAIL();
  } catch (const ParamError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("'a'"), std::string::npos);
    EXPECT_NE(m.find("'b'"), std::string::npos);
    EXPECT_NE(m.find("'count'"), std::string::npos);
    EXPECT_NE(m.find("'sensor'"), std::string::npos);
  }
}

TEST(Params, SchemaRejectsDuplicateAndMistypedDefault) {
  ParamSchema s;
  s.add_bool("x", true, "");
  EXPECT_THROW(s.add_bool("x", false, ""), std::logic_error);
  EXPECT_THROW(s.add(ParamSpec{"y", ParamType::Int, ParamValue{std::string("no")}, "", {}, {}, {}}),
               std::logic_error);
}

TEST(Params, GetWithWrongTypeOrUndeclaredThrows) {
  const auto p = schema().resolve({raw("sensor", "s")}, "c");
  EXPECT_THROW(p.get<std::int64_t>("period_ms"), std::logic_error);
  EXPECT_THROW(p.get<double>("nope"), std::logic_error);
}

TEST(Params, AssignmentParsing) {
  const auto r = parse_param_assignment("label=walk one", "--param");
  EXPECT_EQ(r.key, "label");
  EXPECT_EQ(std::get<std::string>(r.value), "walk one");
  EXPECT_THROW(parse_param_assignment("novalue", "--param"), ParamError);
  EXPECT_THROW(parse_param_assignment("=3", "--param"), ParamError);
}

// "-p sensors=a:0,1.2,2,180,b:2,1.2,0,270" reaches the list split at every comma.
TEST(Params, NamedItemsSplitAtCommasAreJoinedAgain) {
  EXPECT_EQ(rejoin_named_items({"a:0", "1.2", "2", "180", "b:2", "1.2", "0", "270"}),
            (std::vector<std::string>{"a:0,1.2,2,180", "b:2,1.2,0,270"}));
  EXPECT_EQ(rejoin_named_items({"floor:0,0,0"}), (std::vector<std::string>{"floor:0,0,0"}));
  EXPECT_EQ(rejoin_named_items({"x", "y"}), (std::vector<std::string>{"x,y"}));  // (then refused by the item parser)
  EXPECT_TRUE(rejoin_named_items({}).empty());
}
