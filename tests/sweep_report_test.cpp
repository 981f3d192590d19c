// The sweep's results table and HTML report: CSV round trips, the statistics the report
// prints (checked on hand-made rows), SVG plots and the page structure.
#include <gtest/gtest.h>

#include "common/error.h"
#include "tools/sweep/report_html.h"
#include "tools/sweep/svg_plot.h"
#include "tools/sweep/sweep_results.h"

namespace chorus::sweep {
namespace {

SweepRow row(const std::string& scene, int spp, const std::string& method,
             const std::string& combiner, double relMse, double denoiseSeconds = 1.0) {
  SweepRow r;
  r.scene = scene;
  r.spp = spp;
  r.method = method;
  r.combiner = combiner;
  r.members = combiner == "-" ? (method == "noisy" ? 0 : 1) : int(splitCombination(method).size());
  r.relMse = relMse;
  r.dssim = relMse / 2;
  r.psnr = 30;
  r.smape = 0.1;
  r.renderSeconds = spp * 0.1;
  r.denoiseSeconds = denoiseSeconds;
  r.totalSeconds = r.renderSeconds + denoiseSeconds;
  return r;
}

size_t count(const std::string& text, const std::string& what) {
  size_t n = 0;
  for (size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

TEST(SweepResults, CsvRoundTripsWithQuoting) {
  std::vector<SweepRow> rows = {row("a,\"b\"", 4, "nfor+atrous", "ensemble", 0.0123456789),
                                row("plain", 16, "noisy", "-", 1.5)};
  const std::vector<SweepRow> back = parseCsv(toCsv(rows), "x.csv");
  ASSERT_EQ(back.size(), 2u);
  EXPECT_EQ(back[0].scene, "a,\"b\"");
  EXPECT_EQ(back[0].method, "nfor+atrous");
  EXPECT_EQ(back[0].members, 2);
  EXPECT_NEAR(back[0].relMse, 0.0123456789, 1e-12);
  EXPECT_EQ(back[1].spp, 16);
  EXPECT_THROW(parseCsv("not,a,sweep\n", "x.csv"), Error);
  EXPECT_THROW(parseCsv(csvHeader() + "\nscene,4,m\n", "x.csv"), Error);
}

// Two scenes × two spp; combination "a+b" with every combiner.
std::vector<SweepRow> handMadeRows() {
  std::vector<SweepRow> rows;
  for (const char* scene : {"s1", "s2"})
    for (int spp : {4, 16}) {
      const double k = spp == 4 ? 1.0 : 0.25;
      rows.push_back(row(scene, spp, "noisy", "-", 1.0 * k, 0));
      rows.push_back(row(scene, spp, "a", "-", 0.10 * k, 2));
      rows.push_back(row(scene, spp, "b", "-", 0.20 * k, 3));
      // The ensemble beats its best member except on s2 at 16 spp.
      const bool lose = std::string(scene) == "s2" && spp == 16;
      rows.push_back(row(scene, spp, "a+b", "ensemble", (lose ? 0.12 : 0.08) * k, 5.5));
      rows.push_back(row(scene, spp, "a+b", "onehot-pre", 0.09 * k, 5.4));
      rows.push_back(row(scene, spp, "a+b", "average", 0.13 * k, 5.1));
    }
  return rows;
}

TEST(SweepReport, EnsembleWinsCountsHandMadeCases) {
  const auto rows = handMadeRows();
  // Best member: wins in 3 of 4 cases.
  EXPECT_EQ(ensembleWins(rows, "best-member").cases, 4);
  EXPECT_EQ(ensembleWins(rows, "best-member").wins, 3);
  EXPECT_DOUBLE_EQ(ensembleWins(rows, "best-member").percent(), 75.0);
  EXPECT_EQ(ensembleWins(rows, "best-member", 2, 16).wins, 1);
  EXPECT_EQ(ensembleWins(rows, "onehot-pre").wins, 3);
  EXPECT_EQ(ensembleWins(rows, "average").wins, 4);
  // No onehot-post rows: no cases.
  EXPECT_EQ(ensembleWins(rows, "onehot-post").cases, 0);
}

TEST(SweepReport, AverageRanksByHand) {
  // Ranks per case (1 = lowest relMSE). In three cases: ensemble 1, onehot-pre 2, a 3,
  // average 4, b 5, noisy 6. On s2 at 16 spp: onehot-pre 1, a 2, ensemble 3, then as before.
  const auto ranks = averageRanks(handMadeRows());
  ASSERT_EQ(ranks.size(), 6u);
  EXPECT_EQ(ranks[0].first, "a+b / ensemble");
  EXPECT_DOUBLE_EQ(ranks[0].second, 1.5);  // (1 + 1 + 1 + 3) / 4
  EXPECT_EQ(ranks[1].first, "a+b / onehot-pre");
  EXPECT_DOUBLE_EQ(ranks[1].second, 1.75);  // (2 + 2 + 2 + 1) / 4
  EXPECT_EQ(ranks[2].first, "a");
  EXPECT_DOUBLE_EQ(ranks[2].second, 2.75);
  EXPECT_EQ(ranks[5].first, "noisy");
  EXPECT_DOUBLE_EQ(ranks[5].second, 6.0);
}

TEST(SvgPlot, OnePathPerDrawableSeries) {
  PlotSpec spec;
  spec.title = "t <&>";
  const std::string svg =
      svgLinePlot(spec, {{"a", {{1, 0.1}, {2, 0.05}}, false},
                         {"b", {{1, 0.2}, {10, 0.02}}, true},
                         {"nonpositive", {{1, 0.0}, {2, -1.0}}, false}});  // undrawable on log axes
  EXPECT_EQ(count(svg, "<path class=\"series\""), 2u);
  EXPECT_NE(svg.find("t &lt;&amp;&gt;"), std::string::npos);
  EXPECT_EQ(count(svg, "<svg"), 1u);
}

TEST(SweepReport, Base64KnownVectors) {
  EXPECT_EQ(base64({'M', 'a', 'n'}), "TWFu");
  EXPECT_EQ(base64({'M', 'a'}), "TWE=");
  EXPECT_EQ(base64({'M'}), "TQ==");
  EXPECT_EQ(base64({}), "");
}

TEST(SweepReport, PageHasPlotsTablesAndEveryRow) {
  const auto rows = handMadeRows();
  SceneCrops crops{"s1", 4, {{"noisy", {1, 2, 3}}, {"ensemble", {4, 5}}}, {{"w a", {6}}}};
  const std::string html = buildReportHtml(rows, {crops}, {});
  // 2 scenes × 3 plots; each plot shows noisy, a, b and the 3 combiners of a+b.
  EXPECT_EQ(count(html, "<svg"), 6u);
  EXPECT_EQ(count(html, "<path class=\"series\""), 6u * 6u);
  EXPECT_EQ(count(html, "data:image/png;base64,"), 3u);
  const size_t results = html.find("id=\"results\"");
  ASSERT_NE(results, std::string::npos);
  EXPECT_EQ(count(html.substr(results), "<tr><td>"), rows.size());
  EXPECT_NE(html.find("data-report-ready"), std::string::npos);
}

}  // namespace
}  // namespace chorus::sweep
