#pragma once
// What a sweep runs: the cases (scene × spp), the combinations of base denoisers evaluated in
// each, and the slice of cases a shard owns. Pure functions, no I/O.
#include <filesystem>
#include <string>
#include <vector>

namespace chorus::sweep {

struct SweepCase {
  std::filesystem::path scenePath;
  std::string scene;  // short unique name used in tables and file names
  int spp = 0;
  // "cases/<scene>_spp<N>": rows and crops of a finished case live under this stem.
  std::string fileStem() const;
};

// Every scene at every spp, scenes in the given order and spp ascending within a scene. Scene
// names are file stems, disambiguated with the parent folder when two scenes share a stem.
std::vector<SweepCase> planCases(const std::vector<std::filesystem::path>& scenes,
                                 const std::vector<int>& spps);

// A shard "I/N" (0 ≤ I < N) owns the cases whose index i has i mod N = I.
struct Shard {
  int index = 0, count = 1;
};
Shard parseShard(const std::string& text);  // throws chorus::Error
std::vector<SweepCase> casesOfShard(const std::vector<SweepCase>& cases, Shard shard);

// The combinations to evaluate: "all" = every subset of `methods` with at least two members
// (smaller first, then in the order of `methods`), or a comma-separated list such as
// "nfor+rdfc,nfor+nlm+atrous" whose members must all be in `methods`. Members of a
// combination are listed in the order of `methods` ("a+b", never "b+a"). Throws chorus::Error.
std::vector<std::string> planCombinations(const std::vector<std::string>& methods,
                                          const std::string& spec);

// Seconds the cases still to run will take, from the finished ones: a case's time modelled as
// a + b·spp (least squares, a and b ≥ 0; render time grows with spp, the denoisers' does not),
// or the mean time while fewer than two distinct spp have finished.
struct FinishedCase {
  int spp = 0;
  double seconds = 0;
};
double estimateRemainingSeconds(const std::vector<FinishedCase>& finished,
                                const std::vector<int>& remainingSpps);

// Parses "4,8,16" into positive integers; throws chorus::Error naming `flag` otherwise.
std::vector<int> parseIntList(const std::string& text, const std::string& flag);

}  // namespace chorus::sweep
