#include "skelgraph/report/report.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <sstream>

namespace skelgraph::report {

namespace {

const char* const kColours[] = {"#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd",
                                "#8c564b", "#e377c2", "#7f7f7f", "#bcbd22", "#17becf"};

std::string fmt(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%.1f", v);
  return b;
}

// A "nice" tick step for a range (1, 2 or 5 times a power of ten).
double nice_step(double range, int ticks) {
  const double raw = range / std::max(1, ticks);
  const double p = std::pow(10.0, std::floor(std::log10(raw)));
  for (double m : {1.0, 2.0, 5.0, 10.0}) {
    if (raw <= m * p) return m * p;
  }
  return 10 * p;
}

}  // namespace

std::string html_escape(const std::string& s) {
  std::string o;
  for (char c : s) {
    switch (c) {
      case '<': o += "&lt;"; break;
      case '>': o += "&gt;"; break;
      case '&': o += "&amp;"; break;
      case '"': o += "&quot;"; break;
      default: o += c;
    }
  }
  return o;
}

namespace {
// The figure's title from the left edge; one too long for the figure is
// squeezed to its width rather than cut off at the edge.
std::string title_text(const std::string& title, int width) {
  const double room = width - 16, guess = 7.3 * static_cast<double>(title.size());  // bold 13 px sans-serif
  std::ostringstream o;
  o << "<text x=\"8\" y=\"16\" font-size=\"13\" font-weight=\"bold\"";
  if (guess > room) o << " textLength=\"" << room << "\" lengthAdjust=\"spacingAndGlyphs\"";
  o << ">" << html_escape(title) << "</text>\n";
  return o.str();
}
}  // namespace

std::string line_plot(const std::string& title, const std::string& x_label, const std::string& y_label,
                      const std::vector<Series>& series, int width, int height) {
  const int left = 56, right = 150, top = 28, bottom = 40;
  const int pw = width - left - right, ph = height - top - bottom;
  double x0 = std::numeric_limits<double>::infinity(), x1 = -x0, y0 = x0, y1 = -x0;
  for (const auto& s : series) {
    for (std::size_t i = 0; i < s.x.size() && i < s.y.size(); ++i) {
      if (!std::isfinite(s.y[i]) || !std::isfinite(s.x[i])) continue;
      x0 = std::min(x0, s.x[i]);
      x1 = std::max(x1, s.x[i]);
      y0 = std::min(y0, s.y[i]);
      y1 = std::max(y1, s.y[i]);
    }
  }
  if (!std::isfinite(x0)) x0 = 0, x1 = 1, y0 = 0, y1 = 1;
  if (x1 - x0 < 1e-9) x1 = x0 + 1;
  if (y1 - y0 < 1e-9) y1 = y0 + 1;
  const double ystep = nice_step(y1 - y0, 5), xstep = nice_step(x1 - x0, 8);
  y0 = std::floor(y0 / ystep) * ystep;
  y1 = std::ceil(y1 / ystep) * ystep;
  const auto X = [&](double x) { return left + (x - x0) / (x1 - x0) * pw; };
  const auto Y = [&](double y) { return top + ph - (y - y0) / (y1 - y0) * ph; };
  std::ostringstream o;
  o << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << width << "\" height=\"" << height
    << "\" font-family=\"sans-serif\" font-size=\"11\">\n"
    << "<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n"
    << title_text(title, width);
  for (double y = y0; y <= y1 + 1e-9; y += ystep) {
    o << "<line x1=\"" << left << "\" x2=\"" << left + pw << "\" y1=\"" << Y(y) << "\" y2=\"" << Y(y)
      << "\" stroke=\"#ddd\"/><text x=\"" << left - 4 << "\" y=\"" << Y(y) + 4 << "\" text-anchor=\"end\">" << fmt(y)
      << "</text>\n";
  }
  for (double x = std::ceil(x0 / xstep) * xstep; x <= x1 + 1e-9; x += xstep) {
    o << "<line x1=\"" << X(x) << "\" x2=\"" << X(x) << "\" y1=\"" << top << "\" y2=\"" << top + ph
      << "\" stroke=\"#eee\"/><text x=\"" << X(x) << "\" y=\"" << top + ph + 14 << "\" text-anchor=\"middle\">" << fmt(x)
      << "</text>\n";
  }
  o << "<rect x=\"" << left << "\" y=\"" << top << "\" width=\"" << pw << "\" height=\"" << ph
    << "\" fill=\"none\" stroke=\"#888\"/>\n"
    << "<text x=\"" << left + pw / 2 << "\" y=\"" << height - 6 << "\" text-anchor=\"middle\">" << html_escape(x_label)
    << "</text>\n<text transform=\"translate(14," << top + ph / 2 << ") rotate(-90)\" text-anchor=\"middle\">"
    << html_escape(y_label) << "</text>\n";
  for (std::size_t k = 0; k < series.size(); ++k) {
    const auto& s = series[k];
    const char* colour = kColours[k % std::size(kColours)];
    std::string path;
    bool pen = false;
    for (std::size_t i = 0; i < s.x.size() && i < s.y.size(); ++i) {
      if (!std::isfinite(s.y[i])) {
        pen = false;
        continue;
      }
      char b[64];
      std::snprintf(b, sizeof b, "%c%.1f %.1f ", pen ? 'L' : 'M', X(s.x[i]), Y(s.y[i]));
      path += b;
      pen = true;
    }
    o << "<path d=\"" << path << "\" fill=\"none\" stroke=\"" << colour << "\" stroke-width=\"" << (k == 0 ? 1.6 : 1.1)
      << "\"/>\n<line x1=\"" << left + pw + 10 << "\" x2=\"" << left + pw + 28 << "\" y1=\"" << top + 8 + 15 * k
      << "\" y2=\"" << top + 8 + 15 * k << "\" stroke=\"" << colour << "\" stroke-width=\"2\"/><text x=\""
      << left + pw + 32 << "\" y=\"" << top + 12 + 15 * k << "\">" << html_escape(s.name) << "</text>\n";
  }
  o << "</svg>\n";
  return o.str();
}

std::string timeline(const std::string& title, const std::vector<Strip>& strips, int width, const std::string& legend) {
  const int left = 90, right = 20, top = 28, row = 16;
  const int pw = width - left - right, height = top + row * static_cast<int>(strips.size()) + 30;
  double x0 = std::numeric_limits<double>::infinity(), x1 = -x0;
  for (const auto& s : strips) {
    for (double x : s.x) {
      x0 = std::min(x0, x);
      x1 = std::max(x1, x);
    }
  }
  if (!std::isfinite(x0)) x0 = 0, x1 = 1;
  if (x1 - x0 < 1e-9) x1 = x0 + 1;
  const auto X = [&](double x) { return left + (x - x0) / (x1 - x0) * pw; };
  std::ostringstream o;
  o << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << width << "\" height=\"" << height
    << "\" font-family=\"sans-serif\" font-size=\"11\">\n<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n"
    << title_text(title, width);
  for (std::size_t k = 0; k < strips.size(); ++k) {
    const auto& s = strips[k];
    const double y = top + row * static_cast<double>(k);
    o << "<text x=\"" << left - 6 << "\" y=\"" << y + 11 << "\" text-anchor=\"end\">" << html_escape(s.name) << "</text>\n"
      << "<rect x=\"" << left << "\" y=\"" << y + 2 << "\" width=\"" << pw << "\" height=\"" << row - 4
      << "\" fill=\"#f3d0d0\"/>\n";
    for (std::size_t i = 0; i < s.x.size(); ++i) {
      if (!s.on[i]) continue;
      std::size_t j = i;
      while (j + 1 < s.x.size() && s.on[j + 1]) ++j;
      const double xe = j + 1 < s.x.size() ? s.x[j + 1] : s.x[j];
      o << "<rect x=\"" << X(s.x[i]) << "\" y=\"" << y + 2 << "\" width=\"" << std::max(0.5, X(xe) - X(s.x[i]))
        << "\" height=\"" << row - 4 << "\" fill=\"" << kColours[2] << "\"/>\n";
      i = j;
    }
  }
  const double ty = top + row * static_cast<double>(strips.size()) + 14;
  o << "<text x=\"" << left << "\" y=\"" << ty << "\">" << fmt(x0) << " s</text><text x=\"" << left + pw << "\" y=\"" << ty
    << "\" text-anchor=\"end\">" << fmt(x1) << " s (" << html_escape(legend) << ")</text>\n</svg>\n";
  return o.str();
}

std::string confusion_matrix(const std::string& title, const std::vector<std::string>& labels,
                             const std::vector<std::vector<int>>& counts) {
  const int K = static_cast<int>(labels.size()), cell = 56, left = 130, top = 120;
  const int width = left + K * cell + 20, height = top + K * cell + 50;
  std::ostringstream s;
  s << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << width << "\" height=\"" << height
    << "\" font-family=\"sans-serif\" font-size=\"12\">\n<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n";
  s << "<text x=\"10\" y=\"20\" font-size=\"14\">" << html_escape(title) << "</text>\n";
  s << "<text x=\"" << left + K * cell / 2 << "\" y=\"45\" text-anchor=\"middle\">predicted</text>\n";
  s << "<text x=\"15\" y=\"" << top + K * cell / 2 << "\" transform=\"rotate(-90 15 " << top + K * cell / 2
    << ")\" text-anchor=\"middle\">true</text>\n";
  for (int i = 0; i < K; ++i) {
    int row = 0;
    for (int j = 0; j < K; ++j) row += counts[static_cast<std::size_t>(i)][static_cast<std::size_t>(j)];
    s << "<text x=\"" << left - 6 << "\" y=\"" << top + i * cell + cell / 2 + 4 << "\" text-anchor=\"end\">" << html_escape(labels[static_cast<std::size_t>(i)]) << "</text>\n";
    const int x = left + i * cell + cell / 2;
    s << "<text x=\"" << x << "\" y=\"" << top - 6 << "\" transform=\"rotate(-45 " << x << ' ' << top - 6 << ")\">" << html_escape(labels[static_cast<std::size_t>(i)]) << "</text>\n";
    for (int j = 0; j < K; ++j) {
      const int v = counts[static_cast<std::size_t>(i)][static_cast<std::size_t>(j)];
      const double share = row ? static_cast<double>(v) / row : 0.0;
      const int shade = static_cast<int>(255 - 200 * share);
      s << "<rect x=\"" << left + j * cell << "\" y=\"" << top + i * cell << "\" width=\"" << cell << "\" height=\"" << cell
        << "\" fill=\"rgb(" << shade << ',' << shade << ",255)\" stroke=\"#888\"/>\n";
      s << "<text x=\"" << left + j * cell + cell / 2 << "\" y=\"" << top + i * cell + cell / 2 + 4 << "\" text-anchor=\"middle\" fill=\""
        << (share > 0.6 ? "white" : "black") << "\">" << v << "</text>\n";
    }
  }
  s << "</svg>\n";
  return s.str();
}

}  // namespace skelgraph::report
