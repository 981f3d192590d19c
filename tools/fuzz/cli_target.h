#pragma once
// The CLI target: chorus run as a child process on tiny inputs with mutated argument vectors.
// The flags come from each subcommand's --help (so new flags are fuzzed without changes
// here), their values from lists of extremes by type (nan, inf, −1, 0, 2^31, 2^64, 1e309,
// empty, non-numbers, malformed lists and denoiser specs), and file arguments from a pool of
// valid and invalid paths (missing, a directory, a FIFO, /dev/zero, a NaN image, the wrong
// kind of file).
//
// Judging: exit 0 or 2 is expected. A signal, a timeout (unless the flags asked for a huge
// amount of valid work: Slow), exit 1 ("internal error") or any other code is a finding; so
// are, on exit 2, anything but one error line (CLI11's "Run with --help" hint and warnings
// aside) or one longer than 300 characters, or files left in --out; and, on exit 0, a NaN
// flag value or an empty --out accepted, a non-finite value in a written EXR, or a non-finite
// metric printed by `compare`.
#include <filesystem>
#include <string>
#include <vector>

#include "tools/fuzz/fuzz_case.h"
#include "tools/fuzz/fuzz_random.h"
#include "tools/fuzz/sandbox.h"
#include "tools/fuzz/seed_corpus.h"

namespace chorus::fuzz {

struct CliFlag {
  std::string name;                  // "--spp"
  std::string type;                  // INT, UINT, FLOAT, TEXT, or "" for a switch
  std::vector<std::string> choices;  // from "TEXT:{a,b,c}"
};

struct CliCommand {
  std::string name;               // "render"
  std::vector<std::string> base;  // a valid, quick argument vector (placeholders allowed)
  std::vector<CliFlag> flags;
};

struct CliFixtures {
  std::filesystem::path chorus, dir;
  std::vector<CliCommand> commands;
};

// Reads every subcommand's --help and writes the valid inputs under `dir` (a scene, a K = 4
// render.exr rendered by chorus itself, images with NaN pixels, a Tungsten directory, …).
// Throws chorus::Error when chorus cannot be run.
CliFixtures prepareCliFixtures(const std::filesystem::path& chorus,
                               const std::filesystem::path& sourceDir,
                               const std::filesystem::path& seedDir,
                               const std::filesystem::path& dir, const ChildLimits& limits);

// The flags and choices listed in one subcommand's --help text.
std::vector<CliFlag> parseHelpFlags(const std::string& help);

FuzzCase generateCliCase(const CliFixtures& fixtures, FuzzRandom& rng);

// Runs chorus with the case's arguments (working directory: the case directory) and judges it.
Outcome runCliCase(const FuzzCase& fuzzCase, const CliFixtures& fixtures,
                   const std::filesystem::path& caseDir, const ChildLimits& limits);

}  // namespace chorus::fuzz
