#include "tools/sweep/sweep_results.h"

#include <iomanip>
#include <limits>
#include <sstream>

#include "common/atomic_file.h"
#include "common/error.h"
#include "denoise/metrics/metrics.h"

namespace chorus::sweep {

SweepRow measuredRow(const std::string& scene, int spp, const std::string& method,
                     const std::string& combiner, int members, const Image& image,
                     const Image& reference, double renderSeconds, double denoiseSeconds) {
  const ImageMetrics m = computeMetrics(image, reference);
  SweepRow row;
  row.scene = scene;
  row.spp = spp;
  row.method = method;
  row.combiner = combiner;
  row.members = members;
  row.relMse = m.relMse;
  row.dssim = m.dssim;
  row.psnr = m.psnr;
  row.smape = m.smape;
  row.renderSeconds = renderSeconds;
  row.denoiseSeconds = denoiseSeconds;
  row.totalSeconds = renderSeconds + denoiseSeconds;
  return row;
}

namespace {

constexpr int kColumns = 12;

std::string quoteIfNeeded(const std::string& field) {
  if (field.find_first_of(",\"\n") == std::string::npos) return field;
  std::string quoted = "\"";
  for (char c : field) quoted += c == '"' ? std::string("\"\"") : std::string(1, c);
  return quoted + "\"";
}

// Splits one CSV line into fields (RFC 4180 quoting, no embedded newlines).
std::vector<std::string> splitCsvLine(const std::string& line) {
  std::vector<std::string> fields(1);
  bool quoted = false;
  for (size_t i = 0; i < line.size(); ++i) {
    const char c = line[i];
    if (quoted) {
      if (c == '"' && i + 1 < line.size() && line[i + 1] == '"') {
        fields.back() += '"';
        ++i;
      } else if (c == '"') {
        quoted = false;
      } else {
        fields.back() += c;
      }
    } else if (c == '"') {
      quoted = true;
    } else if (c == ',') {
      fields.emplace_back();
    } else if (c != '\r') {
      fields.back() += c;
    }
  }
  return fields;
}

double parseNumber(const std::string& text, const std::filesystem::path& file, int line) {
  try {
    size_t used = 0;
    const double v = std::stod(text, &used);
    if (used == text.size()) return v;
  } catch (const std::exception&) {
  }
  if (text == "inf") return std::numeric_limits<double>::infinity();
  throw fileError(file, "line " + std::to_string(line) + ": '" + text + "' is not a number");
}

}  // namespace

std::string SweepRow::label() const {
  return combiner == "-" ? method : method + " / " + combiner;
}

std::string csvHeader() {
  return "scene,spp,method,combiner,members,relmse,dssim,psnr,smape,render_s,denoise_s,total_s";
}

std::string toCsv(const std::vector<SweepRow>& rows) {
  std::ostringstream out;
  out << csvHeader() << "\n";
  out << std::setprecision(9);
  for (const SweepRow& r : rows)
    out << quoteIfNeeded(r.scene) << ',' << r.spp << ',' << quoteIfNeeded(r.method) << ','
        << quoteIfNeeded(r.combiner) << ',' << r.members << ',' << r.relMse << ',' << r.dssim << ','
        << r.psnr << ',' << r.smape << ',' << r.renderSeconds << ',' << r.denoiseSeconds << ','
        << r.totalSeconds << "\n";
  return out.str();
}

std::vector<SweepRow> parseCsv(const std::string& text, const std::filesystem::path& file) {
  std::istringstream in(text);
  std::string line;
  if (!std::getline(in, line) || line.rfind(csvHeader(), 0) != 0)
    throw fileError(file, "not a chorus sweep table (unexpected header)");
  std::vector<SweepRow> rows;
  for (int number = 2; std::getline(in, line); ++number) {
    if (line.empty()) continue;
    const std::vector<std::string> f = splitCsvLine(line);
    if (int(f.size()) != kColumns)
      throw fileError(file, "line " + std::to_string(number) + " has " + std::to_string(f.size()) +
                                " fields, expected " + std::to_string(kColumns));
    SweepRow r;
    r.scene = f[0];
    r.spp = int(parseNumber(f[1], file, number));
    r.method = f[2];
    r.combiner = f[3];
    r.members = int(parseNumber(f[4], file, number));
    r.relMse = parseNumber(f[5], file, number);
    r.dssim = parseNumber(f[6], file, number);
    r.psnr = parseNumber(f[7], file, number);
    r.smape = parseNumber(f[8], file, number);
    r.renderSeconds = parseNumber(f[9], file, number);
    r.denoiseSeconds = parseNumber(f[10], file, number);
    r.totalSeconds = parseNumber(f[11], file, number);
    rows.push_back(std::move(r));
  }
  return rows;
}

std::vector<SweepRow> readCsv(const std::filesystem::path& file) {
  return parseCsv(readFileBytes(file), file);
}

void writeCsv(const std::filesystem::path& file, const std::vector<SweepRow>& rows) {
  writeTextAtomically(file, toCsv(rows));
}

std::vector<std::string> splitCombination(const std::string& method) {
  std::vector<std::string> members;
  std::stringstream stream(method);
  std::string item;
  while (std::getline(stream, item, '+'))
    if (!item.empty()) members.push_back(item);
  return members;
}

}  // namespace chorus::sweep
