#include "skelgraph/eval/report.hpp"
#include "skelgraph/skeleton/json_number.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <vector>

#include "skelgraph/report/report.hpp"

namespace skelgraph::eval {

bool has_at_use(const OfflineResult& r) {
  return std::any_of(r.streams.begin(), r.streams.end(), [](const StreamScore& s) {
    return std::isfinite(s.at_use.mean_error_cm());
  });
}

// The tables as CSV (RFC 4180): one row per (scenario or recording, stream),
// the Markdown table's columns; an empty field where a figure has no value.
std::string csv_field(const std::string& s) {
  if (s.find_first_of(",\"\n\r") == std::string::npos) return s;
  std::string q = "\"";
  for (char c : s) q += c == '"' ? std::string("\"\"") : std::string(1, c);
  return q + "\"";
}
std::string csv_number(double v, int decimals) {
  if (!std::isfinite(v)) return "";
  char b[32];
  std::snprintf(b, sizeof b, "%.*f", decimals, v);
  return b;
}
std::string csv_header() {
  std::string h = "scenario,stream,fused";
  for (const auto* g : group_names()) h += std::string(",") + g + "_detection_pct," + g + "_error_cm";
  return h + ",mean_error_cm,offsets_removed_error_cm,upper_body_complete_pct,bone_length_sd_cm,ticks,at_use_mean_error_cm\n";
}
std::string csv_rows(const std::string& scenario, const OfflineResult& r) {
  std::string out;
  for (const auto& s : r.streams) {
    out += csv_field(scenario) + "," + csv_field(s.name) + "," + (s.fused ? "1" : "0");
    for (const auto& g : s.accuracy.figures()) out += "," + csv_number(g.detection_pct, 2) + "," + csv_number(g.error_cm, 3);
    out += "," + csv_number(s.accuracy.mean_error_cm(), 3) + "," + csv_number(s.compensated.mean_error_cm(), 3) + "," +
           csv_number(s.steadiness.upper_body_complete_pct(), 2) + "," + csv_number(s.steadiness.mean_bone_sd_cm(), 3) + "," +
           std::to_string(s.ticks) + "," + csv_number(s.at_use.mean_error_cm(), 3) + "\n";
  }
  return out;
}
void write_text_file(const std::filesystem::path& path, const std::string& text) {
  std::ofstream out(path);
  out << text;
  if (!out.flush()) throw std::runtime_error("cannot write " + path.string());
}

// One scenario's part of the HTML report: its table, error over time, the
// traced joint's coordinates against truth, and when the hands were tracked.
// Every figure is also written as its own SVG file next to the report.
std::string report_section(const std::string& dir, const std::string& name, const std::string& title,
                           const OfflineResult& r, const char* joint) {
  std::ostringstream h;
  h << "<h2>" << report::html_escape(title) << "</h2>\n<table><tr><th>stream</th>";
  for (const auto* g : group_names()) h << "<th>" << g << " det %</th><th>" << g << " err cm</th>";
  const bool at_use = has_at_use(r);
  h << "<th>mean err cm</th>" << (at_use ? "<th>at use cm</th>" : "")
    << "<th>offsets removed cm</th><th>upper body %</th><th>bone SD cm</th></tr>\n";
  for (const auto& s : r.streams) {
    // (Cells built as strings: a fixed buffer once cut the row's end off when figures had more digits.)
    const auto td = [](double v, int decimals) {
      const std::string n = csv_number(v, decimals);
      return "<td>" + (n.empty() ? std::string("-") : n) + "</td>";
    };
    h << "<tr><td>" << report::html_escape(s.name) << "</td>";
    for (const auto& g : s.accuracy.figures()) h << td(g.detection_pct, 1) << td(g.error_cm, 1);
    h << "<td><b>" << csv_number(s.accuracy.mean_error_cm(), 1) << "</b></td>";
    if (at_use) h << td(s.at_use.mean_error_cm(), 1);
    h << td(s.compensated.mean_error_cm(), 1)
      << td(s.steadiness.upper_body_complete_pct(), 1) << td(s.steadiness.mean_bone_sd_cm(), 2) << "</tr>\n";
  }
  h << "</table>\n";
  write_text_file(std::filesystem::path(dir) / (name + ".csv"), csv_header() + csv_rows(name, r));
  h << "<p>This table as CSV: <a href=\"" << report::html_escape(name) << ".csv\">" << report::html_escape(name)
    << ".csv</a></p>\n";
  // Reliability of the published uncertainty: nominal level against the share of truth inside it.
  std::vector<report::Series> reliability;
  for (const auto& s : r.streams) {
    const auto curve = s.uncertainty.reliability();
    if (curve.empty()) continue;
    if (reliability.empty()) reliability.push_back({"ideal", {0, 100}, {0, 100}});
    report::Series se{s.name, {}, {}};
    for (const auto& [nominal, observed] : curve) {
      se.x.push_back(nominal);
      se.y.push_back(observed);
    }
    reliability.push_back(std::move(se));
  }
  if (!reliability.empty()) {
    const auto svg = report::line_plot(title + ": truth inside the published region (reliability)",
                                       "nominal level (%)", "truth inside (%)", reliability, 420, 320);
    write_text_file(std::filesystem::path(dir) / (name + "_reliability.svg"), svg);
    h << "<figure>" << svg << "<figcaption>" << report::html_escape(name) << "_reliability.svg</figcaption></figure>\n";
  }
  if (r.streams.empty() || r.streams.front().trace.empty()) return h.str();
  const double t0 = static_cast<double>(r.streams.front().trace.front().t_ns);
  const auto secs = [&](const StreamScore& s) {
    std::vector<double> x;
    for (const auto& p : s.trace) x.push_back((static_cast<double>(p.t_ns) - t0) * 1e-9);
    return x;
  };
  const auto write = [&](const std::string& file, const std::string& svg) {
    std::ofstream out(std::filesystem::path(dir) / file);
    out << svg;
    if (!out.flush()) throw std::runtime_error("cannot write " + (std::filesystem::path(dir) / file).string());
    h << "<figure>" << svg << "<figcaption>" << report::html_escape(file) << "</figcaption></figure>\n";
  };
  // Error over time: the upper body's mean per tick, then each joint group's (the thesis's Fig. 5.2).
  const auto error_series = [&](int group) {  // group -1: the mean over the groups reported at the tick
    std::vector<report::Series> err;
    for (const auto& s : r.streams) {
      report::Series se{s.name, secs(s), {}};
      for (const auto& p : s.trace) {
        if (group >= 0) {
          se.y.push_back(p.error_cm[static_cast<std::size_t>(group)]);
          continue;
        }
        double sum = 0;
        int n = 0;
        for (double e : p.error_cm) {
          if (std::isfinite(e)) sum += e, ++n;
        }
        se.y.push_back(n > 0 ? sum / n : std::nan(""));
      }
      err.push_back(std::move(se));
    }
    return err;
  };
  write(name + "_error.svg",
        report::line_plot(title + ": mean upper-body error per tick", "time (s)", "error (cm)", error_series(-1)));
  const auto group_file = [](const char* group) {
    std::string g = group;
    std::transform(g.begin(), g.end(), g.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    return g;
  };
  h << "<details><summary>Error over time per joint group</summary>\n";
  for (std::size_t g = 0; g < kGroupCount; ++g) {
    const char* group = group_names()[g];
    write(name + "_error_" + group_file(group) + ".svg",
          report::line_plot(title + ": " + group + " error per tick", "time (s)", "error (cm)",
                            error_series(static_cast<int>(g)), 760, 220));
  }
  h << "</details>\n";
  // The traced joint against truth, per coordinate (the thesis's Fig. 5.3/5.4).
  const StreamScore* kalman = nullptr;
  for (const auto& s : r.streams) {
    if (s.name == "kalman") kalman = &s;
  }
  for (int axis = 0; axis < 3; ++axis) {
    std::vector<report::Series> xyz;
    if (kalman != nullptr) {
      report::Series truth{"truth", secs(*kalman), {}};
      for (const auto& p : kalman->trace) truth.y.push_back(p.truth[axis]);
      xyz.push_back(std::move(truth));
    }
    for (const auto& s : r.streams) {
      if (s.fused && s.name != "kalman" && s.name != "avg" && s.name != "live kalman") continue;
      report::Series se{s.name, secs(s), {}};
      for (const auto& p : s.trace) se.y.push_back(p.joint[axis]);
      xyz.push_back(std::move(se));
    }
    const std::string c(1, "xyz"[axis]);
    write(name + "_" + joint + "_" + c + ".svg",
          report::line_plot(title + ": " + joint + " " + c + " (world)", "time (s)", c + " (m)", xyz, 760, 220));
  }
  // Detection timelines: when each group was reported at confidence 1, hands first (what fusion gains most).
  const auto strips_of = [&](std::size_t group) {
    std::vector<report::Strip> strips;
    for (const auto& s : r.streams) {
      report::Strip st{s.name, secs(s), {}};
      for (const auto& p : s.trace) st.on.push_back(std::isfinite(p.error_cm[group]));
      strips.push_back(std::move(st));
    }
    return strips;
  };
  constexpr std::size_t kHands = kGroupCount - 1;
  write(name + "_hands_detected.svg", report::timeline(title + ": hands reported at confidence 1", strips_of(kHands)));
  h << "<details><summary>Detection timelines of the other joint groups</summary>\n";
  for (std::size_t g = 0; g < kHands; ++g) {
    const char* group = group_names()[g];
    write(name + "_" + group_file(group) + "_detected.svg",
          report::timeline(title + ": " + group + " reported at confidence 1", strips_of(g)));
  }
  h << "</details>\n";
  return h.str();
}

// DIR/report.html around the given sections; returns its path.
std::string write_report_page(const std::string& dir, const std::string& heading, const std::string& sections) {
  const auto path = std::filesystem::path(dir) / "report.html";
  std::ofstream f(path);
  f << "<!DOCTYPE html>\n<html><head><meta charset=\"utf-8\"><title>" << report::html_escape(heading)
    << "</title><style>"
       "body{font-family:sans-serif;margin:2em;max-width:1100px}table{border-collapse:collapse;font-size:12px}"
       "td,th{border:1px solid #ccc;padding:2px 6px;text-align:right}td:first-child{text-align:left}"
       "figure{margin:1em 0}</style></head><body>\n<h1>"
    << report::html_escape(heading)
    << "</h1>\n"
       "<p>Detection: % of output ticks (the sync ticks, else 30 Hz) a joint group is reported with confidence 1. "
       "Error: mean distance to truth over those, cm. Single sensors are scored on the same ticks as the fusion "
       "methods; 'offsets removed': after the first 5 s, each stream's constant per-joint offsets (learnt in the "
       "body frame while the person stands still) subtracted. Made by <code>skelgraph eval ... --report</code>; "
       "every figure is also an SVG file in this directory.</p>\n"
    << sections << "</body></html>\n";
  if (!f.flush()) throw std::runtime_error("cannot write " + path.string());
  return path.string();
}

nlohmann::json stream_json(const StreamScore& s) {
  nlohmann::json groups = nlohmann::json::object();
  const auto f = s.accuracy.figures();
  for (std::size_t g = 0; g < kGroupCount; ++g) {
    groups[group_names()[g]] = {{"detection_pct", f[g].detection_pct}, {"error_cm", json_number(f[g].error_cm)}};
  }
  return {{"stream", s.name},
          {"fused", s.fused},
          {"groups", groups},
          {"mean_error_cm", json_number(s.accuracy.mean_error_cm())},
          {"mean_group_error_cm", json_number(s.accuracy.mean_group_error_cm())},
          {"at_use_mean_error_cm", json_number(s.at_use.mean_error_cm())},
          {"at_use_mean_group_error_cm", json_number(s.at_use.mean_group_error_cm())},
          {"after_calibration_mean_error_cm", json_number(s.after_calibration.mean_error_cm())},
          {"compensated_mean_error_cm", json_number(s.compensated.mean_error_cm())},
          {"upper_body_complete_pct", s.steadiness.upper_body_complete_pct()},
          {"upper_body_complete_when_a_single_sensor_is_pct", s.complete_when_single_pct()},
          {"bone_length_sd_cm", json_number(s.steadiness.mean_bone_sd_cm())},
          {"uncertainty",
           {{"joint_ticks", s.uncertainty.joint_ticks()},
            {"inside_95_pct", json_number(s.uncertainty.inside_95_pct())},
            {"sigma_error_spearman", json_number(s.uncertainty.sigma_error_spearman())},
            {"median_sigma_cm", json_number(s.uncertainty.median_sigma_cm())},
            {"reliability", s.uncertainty.reliability()}}},
          {"ticks", s.ticks},
          {"ticks_with_output", s.with_output},
          {"id_switches", s.id_switches},
          {"id_switches_after_gap", s.id_switches_after_gap},
          {"id_switches_per_person_minute", json_number(s.id_switches_per_person_minute())}};
}

}  // namespace skelgraph::eval
