#pragma once
// The evaluation's report (`skelgraph eval ... --report/--csv`, the demo):
// each stream's figures as JSON, the tables as CSV (RFC 4180; one row per scenario or recording and stream,
// the printed table's columns), and the HTML page: per scenario its table,
// the error over time, a joint's coordinates against the truth, when each
// joint group was tracked and how reliable the published uncertainty is,
// every figure also written as its own SVG file (plots: the report library).
// No DDS.

#include <filesystem>
#include <string>

#include <nlohmann/json.hpp>

#include "skelgraph/eval/offline.hpp"

namespace skelgraph::eval {

// Scored at the time of use too (eval --use-delay-ms): the tables get a column.
bool has_at_use(const OfflineResult& r);
std::string csv_field(const std::string& s);
std::string csv_number(double v, int decimals);  // empty where there is no value
std::string csv_header();
// A stream's figures as JSON (the `--json` of every eval command).
nlohmann::json stream_json(const StreamScore& s);
std::string csv_rows(const std::string& scenario, const OfflineResult& r);
void write_text_file(const std::filesystem::path& path, const std::string& text);  // throws std::runtime_error
// One scenario's part of the page (its files written into `dir` as NAME*.csv/svg).
std::string report_section(const std::string& dir, const std::string& name, const std::string& title,
                           const OfflineResult& r, const char* joint);
// DIR/report.html around the given sections; returns its path.
std::string write_report_page(const std::string& dir, const std::string& heading, const std::string& sections);

}  // namespace skelgraph::eval
