// Loads a generated report.html in headless Chromium (Debian's `chromium`, installed by
// `tools/setup.sh test`) and checks the DOM after scripts ran: the page script finished, and
// the expected plots and table rows are there. Skipped when Chromium is absent.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>

#include "tests/support/test_support.h"
#include "tools/sweep/report_html.h"

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

  // Flags as the machine notes recommend for a closed network, running as root.
  const std::string command =
      "timeout 60 " + chromium +
      " --headless --no-sandbox --disable-gpu --disable-quic --no-first-run"
      " --disable-background-networking --disable-component-update --disable-sync"
      " --user-data-dir=" +
      (dir / "profile").string() + " --enable-logging=stderr --v=0 --dump-dom file://" +
      page.string() + " 2>" + (dir / "console.txt").string();
  FILE* pipe = popen(command.c_str(), "r");
  ASSERT_NE(pipe, nullptr);
  std::string dom;
  char buffer[4096];
  for (size_t n; (n = fread(buffer, 1, sizeof buffer, pipe)) > 0;) dom.append(buffer, n);
  const int status = pclose(pipe);
  ASSERT_EQ(status, 0) << "chromium failed";

  // The page script ran to its last statement (no script error stopped it).
  EXPECT_NE(dom.find("data-report-ready=\"yes\""), std::string::npos);
  // 2 scenes × 3 plots × 5 series (noisy, x, y, and the ensemble and onehot-pre of x+y).
  EXPECT_EQ(count(dom, "<svg"), 6u);
  EXPECT_EQ(count(dom, "class=\"series\""), 6u * 5u);
  // Every result is a row of the data table.
  const size_t results = dom.find("id=\"results\"");
  ASSERT_NE(results, std::string::npos);
  EXPECT_EQ(count(dom.substr(results), "<tr><td>"), rows.size());
  // No JavaScript errors on the console.
  std::ifstream console(dir / "console.txt");
  const std::string log((std::istreambuf_iterator<char>(console)), {});
  EXPECT_EQ(log.find("Uncaught"), std::string::npos) << log;
}

}  // namespace
}  // namespace chorus::sweep
