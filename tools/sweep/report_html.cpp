#include "tools/sweep/report_html.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <set>
#include <sstream>

#include "tools/sweep/svg_plot.h"

namespace chorus::sweep {

namespace {

using Case = std::pair<std::string, int>;  // (scene, spp)

std::string fixed(double v, int digits) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, "%.*f", digits, v);
  return buffer;
}

std::string general(double v) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, "%.4g", v);
  return buffer;
}

const SweepRow* findRow(const std::vector<SweepRow>& rows, const std::string& scene, int spp,
                        const std::string& method, const std::string& combiner) {
  for (const SweepRow& r : rows)
    if (r.scene == scene && r.spp == spp && r.method == method && r.combiner == combiner) return &r;
  return nullptr;
}

// The combination with the most members (the "all methods" combination of a sweep).
std::string largestCombination(const std::vector<SweepRow>& rows) {
  std::string best;
  int members = 0;
  for (const SweepRow& r : rows)
    if (r.combiner != "-" && r.members > members) members = r.members, best = r.method;
  return best;
}

std::vector<std::string> scenesOf(const std::vector<SweepRow>& rows) {
  std::vector<std::string> scenes;
  for (const SweepRow& r : rows)
    if (std::find(scenes.begin(), scenes.end(), r.scene) == scenes.end()) scenes.push_back(r.scene);
  return scenes;
}

std::vector<int> sppOf(const std::vector<SweepRow>& rows) {
  std::set<int> spp;
  for (const SweepRow& r : rows) spp.insert(r.spp);
  return {spp.begin(), spp.end()};
}

// The series a scene's plots show: noisy, each single base denoiser, and every combiner of the
// largest combination.
std::vector<std::pair<std::string, std::string>> plottedMethods(const std::vector<SweepRow>& rows) {
  std::vector<std::pair<std::string, std::string>> methods;
  auto add = [&](const std::string& m, const std::string& c) {
    if (std::find(methods.begin(), methods.end(), std::make_pair(m, c)) == methods.end())
      methods.emplace_back(m, c);
  };
  const std::string all = largestCombination(rows);
  for (const SweepRow& r : rows)
    if (r.combiner == "-") add(r.method, r.combiner);
  for (const SweepRow& r : rows)
    if (r.method == all && r.combiner != "-") add(r.method, r.combiner);
  return methods;
}

std::string scenePlots(const std::vector<SweepRow>& rows, const std::string& scene) {
  struct Metric {
    const char* title;
    const char* yLabel;
    double SweepRow::*field;
    bool againstTime;
  };
  const Metric metrics[] = {{"relMSE vs total time", "relMSE", &SweepRow::relMse, true},
                            {"DSSIM vs total time", "DSSIM", &SweepRow::dssim, true},
                            {"relMSE vs samples per pixel", "relMSE", &SweepRow::relMse, false}};
  std::ostringstream html;
  html << "<div class=\"plots\">\n";
  for (const Metric& metric : metrics) {
    std::vector<PlotSeries> series;
    for (const auto& [method, combiner] : plottedMethods(rows)) {
      PlotSeries s;
      s.name = combiner == "-" ? method : (combiner + " (all)");
      s.emphasised = combiner == "ensemble";
      for (int spp : sppOf(rows))
        if (const SweepRow* r = findRow(rows, scene, spp, method, combiner))
          s.points.emplace_back(metric.againstTime ? r->totalSeconds : double(spp),
                                r->*metric.field);
      series.push_back(std::move(s));
    }
    PlotSpec spec;
    spec.title = scene + ": " + metric.title;
    spec.xLabel = metric.againstTime ? "total seconds (render + denoise)" : "samples per pixel";
    spec.yLabel = metric.yLabel;
    html << svgLinePlot(spec, series);
  }
  html << "</div>\n";
  return html.str();
}

std::string rankingTable(const std::vector<SweepRow>& allRows) {
  // The oracles need the reference, so they are bounds, not methods: ranked without them.
  std::vector<SweepRow> rows;
  for (const SweepRow& r : allRows)
    if (r.combiner.rfind("oracle", 0) != 0) rows.push_back(r);
  std::map<std::string, std::vector<const SweepRow*>> byLabel;
  for (const SweepRow& r : rows) byLabel[r.label()].push_back(&r);
  std::ostringstream html;
  html << "<table class=\"sortable\" id=\"ranking\"><thead><tr><th>#</th><th>method</th>"
          "<th>combiner</th><th>members</th><th>average rank</th><th>mean relMSE</th>"
          "<th>mean DSSIM</th><th>mean total s</th></tr></thead><tbody>\n";
  int position = 1;
  for (const auto& [label, rank] : averageRanks(rows)) {
    const auto& group = byLabel[label];
    double relMse = 0, dssim = 0, seconds = 0;
    for (const SweepRow* r : group)
      relMse += r->relMse, dssim += r->dssim, seconds += r->totalSeconds;
    const double n = double(group.size());
    html << "<tr><td>" << position++ << "</td><td>" << escapeXml(group[0]->method) << "</td><td>"
         << escapeXml(group[0]->combiner) << "</td><td>" << group[0]->members << "</td><td>"
         << fixed(rank, 2) << "</td><td>" << general(relMse / n) << "</td><td>"
         << general(dssim / n) << "</td><td>" << general(seconds / n) << "</td></tr>\n";
  }
  html << "</tbody></table>\n";
  return html.str();
}

// The paper's Tables 1–2: rows = number of base denoisers, columns = spp, cells = % of cases
// where the ensemble beats `other`.
std::string winsTable(const std::vector<SweepRow>& rows, const std::string& other,
                      const std::string& caption) {
  std::set<int> sizes;
  for (const SweepRow& r : rows)
    if (r.combiner == "ensemble") sizes.insert(r.members);
  const std::vector<int> spps = sppOf(rows);
  std::ostringstream html;
  html << "<table class=\"wins\"><caption>" << escapeXml(caption)
       << "</caption><thead><tr><th>base denoisers</th>";
  for (int spp : spps) html << "<th>" << spp << " spp</th>";
  html << "<th>all</th></tr></thead><tbody>\n";
  auto cell = [&](int members, int spp) {
    const EnsembleWins w = ensembleWins(rows, other, members, spp);
    return w.cases ? fixed(w.percent(), 0) + "% <small>(" + std::to_string(w.wins) + "/" +
                         std::to_string(w.cases) + ")</small>"
                   : std::string("–");
  };
  for (int members : sizes) {
    html << "<tr><td>" << members << "</td>";
    for (int spp : spps) html << "<td>" << cell(members, spp) << "</td>";
    html << "<td>" << cell(members, 0) << "</td></tr>\n";
  }
  html << "<tr><td>all</td>";
  for (int spp : spps) html << "<td>" << cell(0, spp) << "</td>";
  html << "<td>" << cell(0, 0) << "</td></tr>\n</tbody></table>\n";
  return html.str();
}

std::string overheadParagraph(const std::vector<SweepRow>& rows) {
  // Time the ensemble adds on top of running its members: its denoise time minus theirs.
  double overhead = 0, members = 0;
  int cases = 0;
  for (const SweepRow& r : rows) {
    if (r.combiner != "ensemble") continue;
    double sum = 0;
    bool complete = true;
    for (const std::string& m : splitCombination(r.method)) {
      const SweepRow* single = findRow(rows, r.scene, r.spp, m, "-");
      if (!single)
        complete = false;
      else
        sum += single->denoiseSeconds;
    }
    if (!complete) continue;
    overhead += r.denoiseSeconds - sum;
    members += sum;
    ++cases;
  }
  if (cases == 0) return "";
  return "<p>Ensemble cost over running its members once on the full buffer (their runs on "
         "halves A and B, plus the weight solve, filter and blend): " +
         general(overhead / cases) + " s per combination on average, " +
         fixed(members > 0 ? 100.0 * overhead / members : 0.0, 1) +
         "% of the members' full-buffer time (the half runs alone account for about 200%).</p>\n";
}

std::string imageGrid(const std::vector<ReportImage>& images, const char* cssClass) {
  std::ostringstream html;
  html << "<div class=\"" << cssClass << "\">";
  for (const ReportImage& image : images)
    html << "<figure><img alt=\"" << escapeXml(image.label) << "\" src=\"data:image/png;base64,"
         << base64(image.png) << "\"><figcaption>" << escapeXml(image.label)
         << "</figcaption></figure>";
  html << "</div>\n";
  return html.str();
}

std::string allRowsTable(const std::vector<SweepRow>& rows) {
  std::ostringstream html;
  html << "<details><summary>All " << rows.size() << " results</summary>\n"
       << "<table class=\"sortable\" id=\"results\"><thead><tr><th>scene</th><th>spp</th>"
          "<th>method</th><th>combiner</th><th>relMSE</th><th>DSSIM</th><th>PSNR</th>"
          "<th>SMAPE</th><th>render s</th><th>denoise s</th><th>total s</th></tr></thead><tbody>\n";
  for (const SweepRow& r : rows)
    html << "<tr><td>" << escapeXml(r.scene) << "</td><td>" << r.spp << "</td><td>"
         << escapeXml(r.method) << "</td><td>" << escapeXml(r.combiner) << "</td><td>"
         << general(r.relMse) << "</td><td>" << general(r.dssim) << "</td><td>" << fixed(r.psnr, 2)
         << "</td><td>" << general(r.smape) << "</td><td>" << general(r.renderSeconds)
         << "</td><td>" << general(r.denoiseSeconds) << "</td><td>" << general(r.totalSeconds)
         << "</td></tr>\n";
  html << "</tbody></table></details>\n";
  return html.str();
}

const char* kStyle = R"(
body { font-family: sans-serif; margin: 1.5em; color: #222; max-width: 1400px; }
h1 { font-size: 1.5em; } h2 { font-size: 1.2em; margin-top: 1.6em; }
table { border-collapse: collapse; margin: 0.6em 0; font-size: 0.9em; }
th, td { border: 1px solid #ccc; padding: 2px 7px; text-align: right; }
th { background: #f3f3f3; cursor: pointer; } td:nth-child(2), td:nth-child(3) { text-align: left; }
caption { text-align: left; font-weight: bold; padding: 4px 0; }
.plots { display: flex; flex-wrap: wrap; gap: 8px; }
.crops, .weights { display: flex; flex-wrap: wrap; gap: 6px; }
figure { margin: 0; } figure img { width: 160px; image-rendering: pixelated; display: block; }
figcaption { font-size: 0.8em; text-align: center; }
.details { color: #555; font-size: 0.9em; white-space: pre-wrap; }
)";

// Click a header to sort; the last statement marks the page as fully initialised (the browser
// test checks for it).
const char* kScript = R"(
document.querySelectorAll('table.sortable').forEach(function (table) {
  table.querySelectorAll('th').forEach(function (th, column) {
    th.addEventListener('click', function () {
      var body = table.tBodies[0];
      var rows = Array.prototype.slice.call(body.rows);
      var numeric = rows.every(function (r) { return !isNaN(parseFloat(r.cells[column].textContent)); });
      rows.sort(function (a, b) {
        var x = a.cells[column].textContent, y = b.cells[column].textContent;
        return numeric ? parseFloat(x) - parseFloat(y) : x.localeCompare(y);
      });
      rows.forEach(function (r) { body.appendChild(r); });
    });
  });
});
// Decoded crops, counted once everything loaded (the browser test checks them too).
window.addEventListener('load', function () {
  var decoded = Array.prototype.filter.call(document.images, function (image) {
    return image.complete && image.naturalWidth > 0;
  });
  document.body.setAttribute('data-images-decoded', String(decoded.length));
});
document.body.setAttribute('data-report-ready', 'yes');
)";

}  // namespace

std::string base64(const std::vector<uint8_t>& bytes) {
  static const char* alphabet = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((bytes.size() + 2) / 3 * 4);
  for (size_t i = 0; i < bytes.size(); i += 3) {
    const uint32_t b0 = bytes[i];
    const uint32_t b1 = i + 1 < bytes.size() ? bytes[i + 1] : 0;
    const uint32_t b2 = i + 2 < bytes.size() ? bytes[i + 2] : 0;
    const uint32_t triple = (b0 << 16) | (b1 << 8) | b2;
    out += alphabet[(triple >> 18) & 63];
    out += alphabet[(triple >> 12) & 63];
    out += i + 1 < bytes.size() ? alphabet[(triple >> 6) & 63] : '=';
    out += i + 2 < bytes.size() ? alphabet[triple & 63] : '=';
  }
  return out;
}

EnsembleWins ensembleWins(const std::vector<SweepRow>& rows, const std::string& other, int members,
                          int spp) {
  EnsembleWins wins;
  for (const SweepRow& r : rows) {
    if (r.combiner != "ensemble" || (members && r.members != members) || (spp && r.spp != spp))
      continue;
    double otherRelMse = INFINITY;
    if (other == "best-member") {
      for (const std::string& m : splitCombination(r.method))
        if (const SweepRow* single = findRow(rows, r.scene, r.spp, m, "-"))
          otherRelMse = std::min(otherRelMse, single->relMse);
    } else if (const SweepRow* o = findRow(rows, r.scene, r.spp, r.method, other)) {
      otherRelMse = o->relMse;
    }
    if (!std::isfinite(otherRelMse)) continue;
    ++wins.cases;
    wins.wins += r.relMse < otherRelMse;
  }
  return wins;
}

std::vector<std::pair<std::string, double>> averageRanks(const std::vector<SweepRow>& rows) {
  std::map<Case, std::vector<const SweepRow*>> cases;
  for (const SweepRow& r : rows) cases[{r.scene, r.spp}].push_back(&r);
  std::map<std::string, std::pair<double, int>> rankSum;  // label → (sum, count)
  for (auto& [key, group] : cases) {
    std::stable_sort(group.begin(), group.end(),
                     [](const SweepRow* a, const SweepRow* b) { return a->relMse < b->relMse; });
    for (size_t i = 0; i < group.size(); ++i) {
      auto& entry = rankSum[group[i]->label()];
      entry.first += double(i + 1);
      entry.second += 1;
    }
  }
  std::vector<std::pair<std::string, double>> ranks;
  for (const auto& [label, entry] : rankSum)
    if (entry.second == int(cases.size())) ranks.emplace_back(label, entry.first / entry.second);
  std::stable_sort(ranks.begin(), ranks.end(),
                   [](const auto& a, const auto& b) { return a.second < b.second; });
  return ranks;
}

std::string buildReportHtml(const std::vector<SweepRow>& rows, const std::vector<SceneCrops>& crops,
                            const ReportInfo& info) {
  std::ostringstream html;
  html << "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>"
       << escapeXml(info.title) << "</title><style>" << kStyle << "</style></head><body>\n"
       << "<h1>" << escapeXml(info.title) << "</h1>\n<p class=\"details\">"
       << escapeXml(info.details) << "</p>\n";

  html << "<h2>Summary</h2>\n<ul>";
  for (const auto& [other, text] : std::vector<std::pair<std::string, std::string>>{
           {"best-member", "its best single member"},
           {"onehot-pre", "one-hot selection (pre-filtered)"},
           {"onehot-post", "one-hot selection (post-filtered)"},
           {"average", "the plain average"}}) {
    const EnsembleWins w = ensembleWins(rows, other);
    if (w.cases)
      html << "<li>The ensemble beats " << text << " in " << fixed(w.percent(), 1) << "% of "
           << w.cases << " cases.</li>";
  }
  html << "</ul>\n" << overheadParagraph(rows);

  for (const std::string& scene : scenesOf(rows))
    html << "<h2>" << escapeXml(scene) << "</h2>\n" << scenePlots(rows, scene);

  html << "<h2>Ranking (average rank by relMSE over every scene and spp; oracles left out)</h2>\n"
       << rankingTable(rows);

  html << "<h2>Ensemble against other combiners</h2>\n"
       << winsTable(rows, "onehot-pre", "Ensemble beats one-hot (pre-filtered estimates)")
       << winsTable(rows, "onehot-post", "Ensemble beats one-hot (post-filtered maps)")
       << winsTable(rows, "best-member", "Ensemble beats its best single member");

  if (!crops.empty()) html << "<h2>Crops</h2>\n";
  for (const SceneCrops& c : crops) {
    html << "<h3>" << escapeXml(c.scene) << " at " << c.spp << " spp</h3>\n"
         << imageGrid(c.images, "crops");
    if (!c.weightMaps.empty())
      html << "<p>Ensemble weights (false colour: dark blue 0 → yellow 1)</p>\n"
           << imageGrid(c.weightMaps, "weights");
  }

  html << "<h2>Data</h2>\n" << allRowsTable(rows);
  html << "<script>" << kScript << "</script>\n</body></html>\n";
  return html.str();
}

}  // namespace chorus::sweep
