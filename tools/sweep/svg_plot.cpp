#include "tools/sweep/svg_plot.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

namespace chorus::sweep {

namespace {

struct Axis {
  bool log = true;
  double lo = 0, hi = 1;  // in transformed units (log10 when log)

  double transform(double v) const { return log ? std::log10(v) : v; }
  bool drawable(double v) const { return std::isfinite(v) && (!log || v > 0); }
};

std::string formatNumber(double v) {
  char buffer[32];
  const double a = std::abs(v);
  if (v != 0 && (a < 1e-3 || a >= 1e5))
    std::snprintf(buffer, sizeof buffer, "%.0e", v);
  else
    std::snprintf(buffer, sizeof buffer, "%g", v);
  return buffer;
}

// Tick positions (in data units) covering [lo, hi] (transformed units).
std::vector<double> ticks(const Axis& axis) {
  std::vector<double> t;
  if (axis.log) {
    const int first = int(std::floor(axis.lo)), last = int(std::ceil(axis.hi));
    const bool fewDecades = last - first <= 2;
    for (int e = first; e <= last; ++e)
      for (double m : fewDecades ? std::vector<double>{1, 2, 5} : std::vector<double>{1}) {
        const double v = m * std::pow(10.0, e);
        const double tv = std::log10(v);
        if (tv >= axis.lo - 1e-9 && tv <= axis.hi + 1e-9) t.push_back(v);
      }
  } else {
    const double span = axis.hi - axis.lo;
    const double step = std::pow(10.0, std::floor(std::log10(span / 4)));
    for (double v = std::ceil(axis.lo / step) * step; v <= axis.hi + 1e-12; v += step)
      t.push_back(v);
  }
  return t;
}

Axis fitAxis(bool log, const std::vector<double>& values) {
  Axis axis;
  axis.log = log;
  double lo = INFINITY, hi = -INFINITY;
  for (double v : values)
    if (axis.drawable(v)) {
      lo = std::min(lo, axis.transform(v));
      hi = std::max(hi, axis.transform(v));
    }
  if (!std::isfinite(lo)) return axis;
  if (hi - lo < 1e-9) {
    lo -= log ? 0.5 : std::max(1.0, std::abs(lo) * 0.1);
    hi += log ? 0.5 : std::max(1.0, std::abs(hi) * 0.1);
  }
  const double pad = 0.04 * (hi - lo);
  axis.lo = lo - pad;
  axis.hi = hi + pad;
  return axis;
}

}  // namespace

std::string escapeXml(const std::string& text) {
  std::string out;
  for (char c : text) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

std::string seriesColor(size_t index) {
  static const char* palette[] = {"#4e79a7", "#f28e2b", "#e15759", "#76b7b2", "#59a14f",
                                  "#edc948", "#b07aa1", "#ff9da7", "#9c755f", "#bab0ac"};
  return palette[index % 10];
}

std::string svgLinePlot(const PlotSpec& spec, const std::vector<PlotSeries>& series) {
  std::vector<double> xs, ys;
  for (const PlotSeries& s : series)
    for (const auto& [x, y] : s.points) xs.push_back(x), ys.push_back(y);
  const Axis ax = fitAxis(spec.logX, xs), ay = fitAxis(spec.logY, ys);

  const double legendWidth = 190, left = 64, right = legendWidth + 12, top = 30, bottom = 46;
  const double plotW = spec.width - left - right, plotH = spec.height - top - bottom;
  auto px = [&](double x) { return left + (ax.transform(x) - ax.lo) / (ax.hi - ax.lo) * plotW; };
  auto py = [&](double y) { return top + (ay.hi - ay.transform(y)) / (ay.hi - ay.lo) * plotH; };

  std::ostringstream svg;
  svg.setf(std::ios::fixed);
  svg.precision(1);
  svg << "<svg xmlns=\"http://www.w3.org/2000/svg\" class=\"plot\" width=\"" << spec.width
      << "\" height=\"" << spec.height << "\" viewBox=\"0 0 " << spec.width << ' ' << spec.height
      << "\" font-family=\"sans-serif\" font-size=\"11\">\n";
  svg << "<text x=\"" << left + plotW / 2 << "\" y=\"18\" text-anchor=\"middle\" font-size=\"13\">"
      << escapeXml(spec.title) << "</text>\n";
  svg << "<rect x=\"" << left << "\" y=\"" << top << "\" width=\"" << plotW << "\" height=\""
      << plotH << "\" fill=\"none\" stroke=\"#888\"/>\n";
  for (double t : ticks(ax)) {
    const double x = px(t);
    svg << "<line x1=\"" << x << "\" y1=\"" << top << "\" x2=\"" << x << "\" y2=\"" << top + plotH
        << "\" stroke=\"#eee\"/><text x=\"" << x << "\" y=\"" << top + plotH + 14
        << "\" text-anchor=\"middle\">" << formatNumber(t) << "</text>\n";
  }
  for (double t : ticks(ay)) {
    const double y = py(t);
    svg << "<line x1=\"" << left << "\" y1=\"" << y << "\" x2=\"" << left + plotW << "\" y2=\"" << y
        << "\" stroke=\"#eee\"/><text x=\"" << left - 4 << "\" y=\"" << y + 4
        << "\" text-anchor=\"end\">" << formatNumber(t) << "</text>\n";
  }
  svg << "<text x=\"" << left + plotW / 2 << "\" y=\"" << spec.height - 8
      << "\" text-anchor=\"middle\">" << escapeXml(spec.xLabel) << "</text>\n";
  svg << "<text transform=\"translate(14," << top + plotH / 2
      << ") rotate(-90)\" text-anchor=\"middle\">" << escapeXml(spec.yLabel) << "</text>\n";

  size_t legendRow = 0;
  for (size_t i = 0; i < series.size(); ++i) {
    const PlotSeries& s = series[i];
    std::ostringstream d;
    d.setf(std::ios::fixed);
    d.precision(1);
    std::ostringstream markers;
    markers.setf(std::ios::fixed);
    markers.precision(1);
    int drawn = 0;
    for (const auto& [x, y] : s.points) {
      if (!ax.drawable(x) || !ay.drawable(y)) continue;
      d << (drawn++ ? " L" : "M") << px(x) << ',' << py(y);
      markers << "<circle cx=\"" << px(x) << "\" cy=\"" << py(y) << "\" r=\"2.5\" fill=\""
              << seriesColor(i) << "\"><title>" << escapeXml(s.name) << ": " << formatNumber(x)
              << ", " << formatNumber(y) << "</title></circle>";
    }
    if (drawn == 0) continue;
    svg << "<path class=\"series\" d=\"" << d.str() << "\" fill=\"none\" stroke=\""
        << seriesColor(i) << "\" stroke-width=\"" << (s.emphasised ? 3 : 1.5) << "\"/>"
        << markers.str() << '\n';
    const double ly = top + 6 + 15.0 * double(legendRow++);
    const double lx = left + plotW + 12;
    svg << "<line x1=\"" << lx << "\" y1=\"" << ly << "\" x2=\"" << lx + 16 << "\" y2=\"" << ly
        << "\" stroke=\"" << seriesColor(i) << "\" stroke-width=\"" << (s.emphasised ? 3 : 1.5)
        << "\"/><text x=\"" << lx + 20 << "\" y=\"" << ly + 4 << "\">" << escapeXml(s.name)
        << "</text>\n";
  }
  if (legendRow == 0)
    svg << "<text x=\"" << left + plotW / 2 << "\" y=\"" << top + plotH / 2
        << "\" text-anchor=\"middle\" fill=\"#888\">no data</text>\n";
  svg << "</svg>\n";
  return svg.str();
}

}  // namespace chorus::sweep
