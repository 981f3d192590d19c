#pragma once
// The layout of a sweep's output directory, and the steps that only read and write it:
//
//   DIR/references/<scene>.exr   rendered references (reused by reruns and other shards)
//   DIR/cases/<stem>.csv         the rows of one finished case (written last, atomically:
//                                its presence means the case is complete)
//   DIR/cases/<stem>/            its crops: crops.tsv (labels → files) and small PNGs
//   DIR/results.csv              every case's rows, sorted by scene and spp
//   DIR/report.html              the self-contained report
#include <filesystem>
#include <string>
#include <vector>

#include "tools/sweep/report_html.h"
#include "tools/sweep/sweep_plan.h"
#include "tools/sweep/sweep_results.h"

namespace chorus::sweep {

std::filesystem::path caseCsvPath(const std::filesystem::path& dir, const SweepCase& c);
std::filesystem::path referencePath(const std::filesystem::path& dir, const std::string& scene);
// DIR/settings.txt: the settings every row of the directory was computed with.
std::filesystem::path settingsPath(const std::filesystem::path& dir);

// Writes the PNGs of `crops` and their manifest under DIR/cases/<stem>/ (manifest last).
void writeCaseCrops(const std::filesystem::path& dir, const SweepCase& c, const SceneCrops& crops);

// Every case's rows and crops found in DIR, then DIR/results.csv and DIR/report.html. Returns
// the rows. Throws chorus::Error naming the file for an unreadable case file.
std::vector<SweepRow> writeSweepSummary(const std::filesystem::path& dir, const ReportInfo& info);

// Copies cases/ and references/ of every input sweep directory (e.g. the shards of a job array)
// into `out` and writes its summary. A file present in two inputs with different content is an
// error naming both (nothing is silently dropped); identical copies are fine.
std::vector<SweepRow> mergeSweeps(const std::filesystem::path& out,
                                  const std::vector<std::filesystem::path>& inputs,
                                  const ReportInfo& info);

}  // namespace chorus::sweep
