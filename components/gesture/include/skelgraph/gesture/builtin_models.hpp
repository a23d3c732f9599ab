#pragma once
// Models built with the project: the build trains them (components/gesture/tools/
// build_model.cpp) into share/skelgraph/models/NAME.json of the build tree, so a
// launch file's `model: sim` loads a file instead of training at every start.
#include <filesystem>
#include <string>
#include <vector>

#include "skelgraph/gesture/classifier.hpp"

namespace skelgraph::gesture {

// The names `model:` accepts besides a file: "sim" (pointing, trained on the
// simulator's sessions as `skelgraph gesture sim` trains it).
const std::vector<std::string>& builtin_model_names();
bool is_builtin_model(const std::string& name);
// $SKELGRAPH_MODEL_DIR, else the build tree's share/skelgraph/models.
std::filesystem::path builtin_model_dir();
std::filesystem::path builtin_model_path(const std::string& name);
// Throws std::invalid_argument naming the file and how to build it when it is missing.
Classifier load_builtin_model(const std::string& name);

}  // namespace skelgraph::gesture
