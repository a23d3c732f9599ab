#include "skelgraph/gesture/builtin_models.hpp"

#include <algorithm>
#include <cstdlib>
#include <stdexcept>

#ifndef SKELGRAPH_MODEL_DIR
#define SKELGRAPH_MODEL_DIR ""
#endif

namespace skelgraph::gesture {

const std::vector<std::string>& builtin_model_names() {
  static const std::vector<std::string> names{"sim"};
  return names;
}

bool is_builtin_model(const std::string& name) {
  const auto& n = builtin_model_names();
  return std::find(n.begin(), n.end(), name) != n.end();
}

std::filesystem::path builtin_model_dir() {
  if (const char* d = std::getenv("SKELGRAPH_MODEL_DIR"); d && *d) return d;
  return SKELGRAPH_MODEL_DIR;
}

std::filesystem::path builtin_model_path(const std::string& name) { return builtin_model_dir() / (name + ".json"); }

Classifier load_builtin_model(const std::string& name) {
  if (!is_builtin_model(name)) throw std::invalid_argument("no built-in gesture model '" + name + "'");
  const auto path = builtin_model_path(name);
  if (!std::filesystem::exists(path))
    throw std::invalid_argument("the built-in gesture model '" + name + "' is missing: " + path.string() +
                                " (the build makes it: cmake --build build --target gesture_models; or set SKELGRAPH_MODEL_DIR)");
  return Classifier::load(path.string());
}

}  // namespace skelgraph::gesture
