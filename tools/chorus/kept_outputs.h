#pragma once
// --keep of `chorus render` and `chorus denoise`: the files written only on request. By default
// a run writes what a user looks at (the denoised image, the noisy colour, stats.json) and, for
// a render, render.exr; --keep members adds each member's own output (<member>.exr: its runs on
// the full buffer and on halves A and B), --keep weights the combination's weight maps
// (weights.exr). At 512², 64 spp with the default members that is 26 and 3 MB of the 80 MB a
// render wrote before (docs/leave-out.md).
#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <string>
#include <vector>

namespace chorus::cli {

struct KeptOutputs {
  bool members = false, weights = false;

  // --keep LIST (comma-separated: members, weights), checked while parsing: an unknown item is
  // one line naming the flag.
  void addFlag(CLI::App& cmd);
};

// A file a run did not write and the flag that would write it.
struct LeftOut {
  std::string file, how;
};

// stats.json's "outputs": {"written": [...], "left_out": {"nfor.exr": "--keep members", ...}}.
nlohmann::ordered_json outputsJson(const std::vector<std::string>& written,
                                   const std::vector<LeftOut>& leftOut);

}  // namespace chorus::cli
