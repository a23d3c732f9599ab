#pragma once
// A number for a JSON report: finite as it is, NaN or infinity as null (JSON
// has neither). One definition for every report (header-only: the includer
// links nlohmann_json).

#include <cmath>

#include <nlohmann/json.hpp>

namespace skelgraph {

inline nlohmann::json json_number(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); }

}  // namespace skelgraph
