// Loads a generated report.html in headless Chromium (Debian's `chromium`, installed by
// `tools/setup.sh test`) and checks the DOM after scripts ran: the page script finished, and
// the expected plots, table rows and crops are there, for synthetic rows and for a real tiny
// sweep. Skipped when Chromium is absent.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>

#include "tests/support/test_support.h"
#include "tests/support/tiny_sweep.h"
#include "tools/sweep/report_html.h"
#include "tools/sweep/sweep_runner.h"

namespace chorus::sweep {
namespace {

std::string chromiumPath() {
  for (const char* p : {"/usr/bin/chromium", "/usr/bin/chromium-browser"})
    if (std::filesystem::exists(p)) return p;
  return "";
}

size_t count(const std::string& text, const std::string& what) {
  size_t n = 0;
  for (size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

// The DOM of `page` after its scripts ran, and Chromium's console log.
struct LoadedPage {
  std::string dom, console;
};
LoadedPage loadInChromium(const std::string& chromium, const std::filesystem::path& page,
                          const test::TempDir& dir) {
  // Flags as the machine notes recommend for a closed network, running as root.
  const std::string command =
      "timeout 60 " + chromium +
      " --headless --no-sandbox --disable-gpu --disable-quic --no-first-run"
      " --disable-background-networking --disable-component-update --disable-sync"
      " --user-data-dir=" +
      (dir / "profile").string() + " --enable-logging=stderr --v=0 --dump-dom file://" +
      page.string() + " 2>" + (dir / "console.txt").string();
  LoadedPage loaded;
  FILE* pipe = popen(command.c_str(), "r");
  if (!pipe) ADD_FAILURE() << "cannot run chromium";
  if (!pipe) return loaded;
  char buffer[4096];
  for (size_t n; (n = fread(buffer, 1, sizeof buffer, pipe)) > 0;) loaded.dom.append(buffer, n);
  EXPECT_EQ(pclose(pipe), 0) << "chromium failed";
  std::ifstream console(dir / "console.txt");
  loaded.console.assign(std::istreambuf_iterator<char>(console), {});
  return loaded;
}

// The page script ran to its last statement, no script error on the console, and the plots
// and data rows are there.
void expectRendered(const LoadedPage& page, size_t plots, size_t series, size_t rows) {
  EXPECT_NE(page.dom.find("data-report-ready=\"yes\""), std::string::npos);
  EXPECT_EQ(page.console.find("Uncaught"), std::string::npos) << page.console;
  EXPECT_EQ(count(page.dom, "<svg"), plots);
  EXPECT_EQ(count(page.dom, "class=\"series\""), series);
  const size_t results = page.dom.find("id=\"results\"");
  ASSERT_NE(results, std::string::npos);
  EXPECT_EQ(count(page.dom.substr(results), "<tr><td>"), rows);
}

TEST(ReportBrowser, PlotsAndTablesRenderInChromium) {
  const std::string chromium = chromiumPath();
  if (chromium.empty()) GTEST_SKIP() << "chromium is not installed";

  std::vector<SweepRow> rows;
  for (const char* scene : {"room", "glass"})
    for (int spp : {4, 16, 64})
      for (const auto& [method, combiner, relMse] :
           std::vector<std::tuple<std::string, std::string, double>>{{"noisy", "-", 1.0},
                                                                     {"x", "-", 0.2},
                                                                     {"y", "-", 0.3},
                                                                     {"x+y", "ensemble", 0.1},
                                                                     {"x+y", "onehot-pre", 0.15}}) {
        SweepRow r;
        r.scene = scene;
        r.spp = spp;
        r.method = method;
        r.combiner = combiner;
        r.members = combiner == "-" ? 1 : 2;
        r.relMse = relMse / spp;
        r.dssim = relMse / 10;
        r.totalSeconds = spp * 0.01 + 1;
        rows.push_back(r);
      }
  test::TempDir dir;
  const auto page = dir / "report.html";
  std::ofstream(page) << buildReportHtml(rows, {}, {});
  // 2 scenes × 3 plots × 5 series (noisy, x, y, and the ensemble and onehot-pre of x+y).
  expectRendered(loadInChromium(chromium, page, dir), 6, 6 * 5, rows.size());
}

// The report of a real (tiny) sweep, crops included.
TEST(ReportBrowser, RealSweepReportRendersWithCrops) {
  const std::string chromium = chromiumPath();
  if (chromium.empty()) GTEST_SKIP() << "chromium is not installed";
  test::TempDir dir;
  runSweep(test::tinySweepConfig(dir / "sweep"));
  const LoadedPage page = loadInChromium(chromium, dir / "sweep" / "report.html", dir);
  // One scene × 3 plots × (noisy, 2 bases, 5 combiners of the combination); 2 cases' rows.
  expectRendered(page, 3, 3 * 8, 2 * test::kTinySweepRowsPerCase);
  // Per case: noisy, 2 bases, ensemble, reference, and 2 weight maps, as PNG data URIs.
  EXPECT_EQ(count(page.dom, "<img alt="), 2 * 7u);
  EXPECT_EQ(count(page.dom, "src=\"data:image/png;base64,iVBOR"), 2 * 7u);
  EXPECT_NE(page.dom.find("data-images-decoded=\"14\""), std::string::npos);
}

}  // namespace
}  // namespace chorus::sweep
