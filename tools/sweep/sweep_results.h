#pragma once
// One row of a sweep: the error and time of one method (a base denoiser, the noisy input, or a
// combination of base denoisers blended by one combiner) on one scene at one sample count.
// Rows are stored as CSV (results.csv, one file per finished case under cases/).
#include <filesystem>
#include <string>
#include <vector>

#include "common/image/image.h"

namespace chorus::sweep {

struct SweepRow {
  std::string scene;
  int spp = 0;
  std::string method;    // "noisy", a base denoiser ("nfor"), or a combination ("nfor+rdfc")
  std::string combiner;  // "-" for the noisy input and single base denoisers, else the combiner
  int members = 0;       // base denoisers involved (0 for noisy)
  double relMse = 0, dssim = 0, psnr = 0, smape = 0;
  double renderSeconds = 0, denoiseSeconds = 0, totalSeconds = 0;

  // "nfor+rdfc / ensemble", or just "nfor" for a single base denoiser.
  std::string label() const;
};

// A row with the metrics of `image` against `reference`; total seconds = render + denoise.
SweepRow measuredRow(const std::string& scene, int spp, const std::string& method,
                     const std::string& combiner, int members, const Image& image,
                     const Image& reference, double renderSeconds, double denoiseSeconds);

// The CSV header line (no trailing newline) and the text of a whole table.
std::string csvHeader();
std::string toCsv(const std::vector<SweepRow>& rows);
// Parses a CSV written by toCsv. Throws chorus::Error naming `file` on malformed input.
std::vector<SweepRow> parseCsv(const std::string& text, const std::filesystem::path& file);
std::vector<SweepRow> readCsv(const std::filesystem::path& file);
// Atomic write.
void writeCsv(const std::filesystem::path& file, const std::vector<SweepRow>& rows);

// Splits "a+b+c" into its members.
std::vector<std::string> splitCombination(const std::string& method);

}  // namespace chorus::sweep
