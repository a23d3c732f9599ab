#include <gtest/gtest.h>

#include <algorithm>

#include "skelgraph/runtime/registry.hpp"

using namespace skelgraph::runtime;

TEST(Registry, BuiltinComponentsAreRegisteredWithUsableDefaults) {
  const auto r = builtin_registry();
  const auto kinds = r.kinds();
  EXPECT_NE(std::find(kinds.begin(), kinds.end(), "sync_master"), kinds.end());
  EXPECT_NE(std::find(kinds.begin(), kinds.end(), "monitor"), kinds.end());
  EXPECT_TRUE(std::is_sorted(kinds.begin(), kinds.end()));
  for (const auto& e : r.entries()) {
    EXPECT_FALSE(e.info.description.empty()) << e.info.kind;
    EXPECT_TRUE(e.factory) << e.info.kind;
    // Every built-in component can start from its defaults alone.
    EXPECT_NO_THROW(e.info.params.resolve({}, e.info.kind)) << e.info.kind;
    for (const auto& p : e.info.params.specs()) EXPECT_FALSE(p.description.empty()) << e.info.kind << "." << p.name;
  }
  EXPECT_DOUBLE_EQ(r.find("sync_master")->info.params.resolve({}, "x").get<double>("tick_period_ms"), 33.0);
}

TEST(Registry, DuplicateAndEmptyKindsAreRejected) {
  ComponentRegistry r;
  r.add(ComponentInfo{"a", "first", {}}, nullptr);
  EXPECT_THROW(r.add(ComponentInfo{"a", "again", {}}, nullptr), std::logic_error);
  EXPECT_THROW(r.add(ComponentInfo{"", "nameless", {}}, nullptr), std::logic_error);
  EXPECT_EQ(r.find("b"), nullptr);
  EXPECT_EQ(r.find("a")->info.description, "first");
}
