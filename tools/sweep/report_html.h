#pragma once
// The sweep's self-contained HTML report: inline SVG plots, tables, and PNG crops embedded as
// data URIs, so `report.html` can be mailed around and opened offline.
#include <cstdint>
#include <string>
#include <vector>

#include "tools/sweep/sweep_results.h"

namespace chorus::sweep {

struct ReportImage {
  std::string label;
  std::vector<uint8_t> png;  // encoded PNG bytes
};

// Side-by-side crops of one scene at one sample count: noisy, each base output, the ensemble,
// the reference, and the ensemble's weight maps in false colour.
struct SceneCrops {
  std::string scene;
  int spp = 0;
  std::vector<ReportImage> images;
  std::vector<ReportImage> weightMaps;
};

struct ReportInfo {
  std::string title = "chorus sweep";
  std::string details;  // free text: command line, machine, threads
};

std::string buildReportHtml(const std::vector<SweepRow>& rows, const std::vector<SceneCrops>& crops,
                            const ReportInfo& info);

// Statistics the report prints, exposed for the sweep's summary line and for tests.
struct EnsembleWins {
  int cases = 0;  // (scene, spp, combination) triples compared
  int wins = 0;   // the ensemble's relMSE was strictly lower
  double percent() const { return cases ? 100.0 * wins / cases : 0.0; }
};
// Ensemble vs another combiner of the same combination ("onehot-pre", "onehot-post",
// "average"), or vs the best single member when `other` is "best-member". `members` = 0 counts
// every combination size, `spp` = 0 every sample count.
EnsembleWins ensembleWins(const std::vector<SweepRow>& rows, const std::string& other,
                          int members = 0, int spp = 0);

// Average rank by relMSE of every (method, combiner) that appears in every (scene, spp) case,
// best first: {label, average rank}.
std::vector<std::pair<std::string, double>> averageRanks(const std::vector<SweepRow>& rows);

std::string base64(const std::vector<uint8_t>& bytes);

}  // namespace chorus::sweep
