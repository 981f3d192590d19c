#include "tools/sweep/sweep_directory.h"

#include <algorithm>
#include <optional>
#include <sstream>
#include <tuple>

#include "common/atomic_file.h"
#include "common/error.h"

namespace chorus::sweep {

namespace fs = std::filesystem;

namespace {

const char* kCropManifest = "crops.tsv";

// Manifest lines: "scene\t<name>", "spp\t<N>", then "image|weight\t<label>\t<file>".
SceneCrops readCaseCrops(const fs::path& caseDir) {
  const fs::path manifest = caseDir / kCropManifest;
  std::istringstream in(readFileBytes(manifest));
  SceneCrops crops;
  std::string line;
  for (int number = 1; std::getline(in, line); ++number) {
    std::vector<std::string> f;
    std::stringstream fields(line);
    for (std::string item; std::getline(fields, item, '\t');) f.push_back(item);
    if (f.size() == 2 && f[0] == "scene") {
      crops.scene = f[1];
    } else if (f.size() == 2 && f[0] == "spp") {
      crops.spp = std::atoi(f[1].c_str());
    } else if (f.size() == 3 && (f[0] == "image" || f[0] == "weight")) {
      const std::string png = readFileBytes(caseDir / f[2]);
      (f[0] == "image" ? crops.images : crops.weightMaps)
          .push_back({f[1], std::vector<uint8_t>(png.begin(), png.end())});
    } else {
      throw fileError(manifest, "line " + std::to_string(number) + " is malformed");
    }
  }
  return crops;
}

// The finished cases in DIR: file stems of cases/*.csv, in name order.
std::vector<fs::path> caseFiles(const fs::path& dir) {
  std::vector<fs::path> files;
  if (!fs::is_directory(dir / "cases")) return files;
  for (const auto& entry : fs::directory_iterator(dir / "cases"))
    if (entry.is_regular_file() && entry.path().extension() == ".csv")
      files.push_back(entry.path());
  std::sort(files.begin(), files.end());
  return files;
}

// Copies every file under `from` to the same relative path under `to`; a differing file that
// already exists there is a conflict.
void copyTree(const fs::path& from, const fs::path& to) {
  if (!fs::is_directory(from)) return;
  std::vector<fs::path> files;
  for (const auto& entry : fs::recursive_directory_iterator(from))
    if (entry.is_regular_file() && entry.path().string().find(".tmp") == std::string::npos)
      files.push_back(entry.path());
  // Case tables last: their presence marks a case as complete, so an interrupted merge must not
  // leave one without its crops.
  std::sort(files.begin(), files.end(), [](const fs::path& a, const fs::path& b) {
    return std::make_pair(a.extension() == ".csv", a) < std::make_pair(b.extension() == ".csv", b);
  });
  for (const fs::path& file : files) {
    const fs::path target = to / fs::relative(file, from);
    const std::string bytes = readFileBytes(file);
    if (fs::exists(target)) {
      if (readFileBytes(target) != bytes)
        throw fileError(file, "conflicts with " + target.string() +
                                  " (the same case or reference with different content)");
      continue;
    }
    ensureDirectory(target.parent_path());
    writeTextAtomically(target, bytes);
  }
}

}  // namespace

fs::path caseCsvPath(const fs::path& dir, const SweepCase& c) {
  return dir / "cases" / (c.fileStem() + ".csv");
}

fs::path settingsPath(const fs::path& dir) {
  return dir / "settings.txt";
}

fs::path referencePath(const fs::path& dir, const std::string& scene) {
  return dir / "references" / (scene + ".exr");
}

void writeCaseCrops(const fs::path& dir, const SweepCase& c, const SceneCrops& crops) {
  const fs::path caseDir = dir / "cases" / c.fileStem();
  ensureDirectory(caseDir);
  std::ostringstream manifest;
  manifest << "scene\t" << crops.scene << "\nspp\t" << crops.spp << "\n";
  auto write = [&](const std::vector<ReportImage>& images, const std::string& kind) {
    for (size_t i = 0; i < images.size(); ++i) {
      const std::string file = kind + std::to_string(i) + ".png";
      writeTextAtomically(caseDir / file, std::string(images[i].png.begin(), images[i].png.end()));
      manifest << kind << "\t" << images[i].label << "\t" << file << "\n";
    }
  };
  write(crops.images, "image");
  write(crops.weightMaps, "weight");
  writeTextAtomically(caseDir / kCropManifest, manifest.str());
}

std::vector<SweepRow> writeSweepSummary(const fs::path& dir, const ReportInfo& info) {
  std::vector<SweepRow> rows;
  std::vector<SceneCrops> crops;
  for (const fs::path& file : caseFiles(dir)) {
    const std::vector<SweepRow> caseRows = readCsv(file);
    rows.insert(rows.end(), caseRows.begin(), caseRows.end());
    const fs::path caseDir = file.parent_path() / file.stem();
    if (fs::exists(caseDir / kCropManifest)) crops.push_back(readCaseCrops(caseDir));
  }
  // File names sort "room_spp16" before "room_spp4": order by scene, then spp numerically,
  // keeping each case's own row order.
  std::stable_sort(rows.begin(), rows.end(), [](const SweepRow& a, const SweepRow& b) {
    return std::tie(a.scene, a.spp) < std::tie(b.scene, b.spp);
  });
  std::stable_sort(crops.begin(), crops.end(), [](const SceneCrops& a, const SceneCrops& b) {
    return std::tie(a.scene, a.spp) < std::tie(b.scene, b.spp);
  });
  writeCsv(dir / "results.csv", rows);
  writeTextAtomically(dir / "report.html", buildReportHtml(rows, crops, info));
  return rows;
}

std::vector<SweepRow> mergeSweeps(const fs::path& out, const std::vector<fs::path>& inputs,
                                  const ReportInfo& info) {
  for (const fs::path& input : inputs)
    if (!fs::is_directory(input / "cases"))
      throw fileError(input, "is not a sweep directory (no cases/ folder)");
  // Slices of one sweep share its settings; rows of different settings are not comparable.
  std::optional<std::pair<fs::path, std::string>> settings;  // the first input's that has some
  for (const fs::path& input : inputs) {
    if (!fs::exists(settingsPath(input))) continue;
    const std::string text = readFileBytes(settingsPath(input));
    if (!settings)
      settings.emplace(settingsPath(input), text);
    else if (text != settings->second)
      throw fileError(settingsPath(input), "differs from " + settings->first.string() +
                                               ": these sweeps ran with other settings");
  }
  ensureDirectory(out);
  if (settings && !fs::exists(settingsPath(out)))
    writeTextAtomically(settingsPath(out), settings->second);
  for (const fs::path& input : inputs) {
    if (fs::equivalent(input, out)) continue;
    copyTree(input / "cases", out / "cases");
    copyTree(input / "references", out / "references");
  }
  return writeSweepSummary(out, info);
}

}  // namespace chorus::sweep
