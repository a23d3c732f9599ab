#pragma once
// A fresh, empty path under the test's temporary directory (removed first if a run left it).
#include <filesystem>
#include <string>

#include <gtest/gtest.h>

namespace skelgraph::test {

inline std::filesystem::path fresh_path(const std::string& name) {
  const auto p = std::filesystem::path(::testing::TempDir()) / name;
  std::filesystem::remove_all(p);
  return p;
}

}  // namespace skelgraph::test
