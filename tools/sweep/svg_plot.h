#pragma once
// Self-contained SVG line plots (log or linear axes) for the sweep report: no scripts, no
// external resources, so the report opens offline in any browser.
#include <string>
#include <utility>
#include <vector>

namespace chorus::sweep {

struct PlotSeries {
  std::string name;
  std::vector<std::pair<double, double>> points;  // (x, y), drawn in the given order
  bool emphasised = false;                        // drawn thicker (e.g. the ensemble)
};

struct PlotSpec {
  std::string title, xLabel, yLabel;
  bool logX = true, logY = true;
  int width = 640, height = 380;
};

// One <svg> element. Every series with at least one drawable point becomes exactly one
// <path class="series"> (points ≤ 0 are dropped on log axes, non-finite ones always), with a
// legend entry.
std::string svgLinePlot(const PlotSpec& spec, const std::vector<PlotSeries>& series);

// Escapes &, <, >, " for HTML/SVG text and attributes.
std::string escapeXml(const std::string& text);

// The colour of series i (a fixed, colour-blind-friendly palette that repeats).
std::string seriesColor(size_t index);

}  // namespace chorus::sweep
