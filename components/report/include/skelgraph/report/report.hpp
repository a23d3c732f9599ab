#pragma once
// Self-contained figures and an HTML report (inline SVG, no scripts, no
// network): what `skelgraph eval ... --report DIR` writes, and the confusion
// matrices of `skelgraph gesture cv --svg`. std only: no DDS.

#include <string>
#include <vector>

namespace skelgraph::report {

struct Series {
  std::string name;
  std::vector<double> x, y;  // NaN in y breaks the line
};

// A line plot as a standalone SVG document.
std::string line_plot(const std::string& title, const std::string& x_label, const std::string& y_label,
                      const std::vector<Series>& series, int width = 760, int height = 260);

// Rows of a stream-by-stream timeline: a bar where `on` is true.
struct Strip {
  std::string name;
  std::vector<double> x;
  std::vector<bool> on;
};
std::string timeline(const std::string& title, const std::vector<Strip>& strips, int width = 760,
                     const std::string& legend = "green: reported at confidence 1; red: not");

// A confusion matrix as a standalone SVG document: counts[truth][predicted],
// a row and a column per label, each cell shaded by its share of its row.
std::string confusion_matrix(const std::string& title, const std::vector<std::string>& labels,
                             const std::vector<std::vector<int>>& counts);

// The one escaping of text for HTML and SVG (text and attribute values): < > & ".
std::string html_escape(const std::string& s);

}  // namespace skelgraph::report
