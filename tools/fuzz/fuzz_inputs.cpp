// fuzz_inputs: the deterministic mutation fuzzer of chorus's input paths (docs/fuzzing.md).
//
//   build/fuzz/fuzz_inputs --count 2000 --seconds 600 --out fuzz-findings
//   build/fuzz/fuzz_inputs --target gltf --seed 1 --case 1234     # one case again
//   build/fuzz/fuzz_inputs --replay tests/fuzz                     # the regression inputs
//
// Case i of a run is a function of (seed, target, i) alone. Targets take turns (case i goes to
// target i mod T). Every case runs sandboxed (sandbox.h); every input whose outcome is a finding
// is saved under --out/<target>/<i>/ with finding.txt (what was mutated, the outcome, the
// command that reproduces it) and the child's stderr. Exit status: 0 without findings, 1 with,
// 2 for bad usage.
#include <CLI/CLI.hpp>

#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <fstream>
#include <map>
#include <optional>
#include <regex>
#include <sstream>

#include "common/error.h"
#include "tools/fuzz/cli_target.h"
#include "tools/fuzz/file_targets.h"
#include "tools/fuzz/fuzz_case.h"
#include "tools/fuzz/sandbox.h"
#include "tools/fuzz/seed_corpus.h"
#include "tools/fuzz/self_test.h"

namespace chorus::fuzz {
namespace {
namespace fs = std::filesystem;

struct Settings {
  std::vector<std::string> targets = {"all"};
  uint64_t seed = 1;
  uint64_t first = 0, count = 1000;
  double seconds = 0;
  std::optional<uint64_t> onlyCase;
  std::vector<std::string> replay;
  fs::path out = "fuzz-findings", work, chorus = CHORUS_BINARY, source = CHORUS_SOURCE_DIR;
  double timeout = 10, cliTimeout = 30;
  size_t memoryMb = 6144;
  bool verbose = false, selfTest = false;
};

struct Tally {
  std::map<Verdict, unsigned long long> verdicts;
  std::map<std::string, uint64_t> findingClasses;  // summary with numbers masked → count
  double seconds = 0;
  unsigned long long count(Verdict v) const {
    const auto it = verdicts.find(v);
    return it == verdicts.end() ? 0 : it->second;
  }
  unsigned long long cases() const {
    unsigned long long n = 0;
    for (const auto& [v, c] : verdicts) n += c;
    return n;
  }
};

// The driver's state for one run: seeds, CLI fixtures (prepared on first use), limits.
class Driver {
 public:
  explicit Driver(const Settings& s) : settings_(s) {
    work_ = s.work.empty()
                ? fs::temp_directory_path() / ("chorus-fuzz-" + std::to_string(::getpid()))
                : s.work;
    fs::create_directories(work_);
    seeds_ = buildSeedCorpus(s.source, work_ / "seeds");
    limits_ = {s.timeout, s.memoryMb << 20};
    cliLimits_ = {s.cliTimeout, s.memoryMb << 20};
  }
  ~Driver() {
    std::error_code ec;
    if (settings_.work.empty()) fs::remove_all(work_, ec);
  }

  FuzzCase generate(Target target, uint64_t index) {
    FuzzRandom rng = FuzzRandom::forCase(settings_.seed, std::string(targetName(target)), index);
    return target == Target::Cli ? generateCliCase(cli(), rng)
                                 : generateFileCase(target, seeds_, rng);
  }

  // A loaded machine (parallel builds and tests) can push a slow but finite case past its
  // timeout: a case that timed out runs once more with kRetryFactor times the time before its
  // timeout counts as a hang. A real hang hangs again.
  Outcome run(const FuzzCase& fuzzCase) {
    const Outcome outcome = runWithin(fuzzCase, 1);
    return outcome.timedOut ? runWithin(fuzzCase, kRetryFactor) : outcome;
  }

 private:
  static constexpr double kRetryFactor = 4;

  Outcome runWithin(const FuzzCase& fuzzCase, double timeFactor) {
    const fs::path dir = work_ / "case";
    fs::remove_all(dir);
    writeCase(fuzzCase, dir);
    const auto scaled = [&](ChildLimits limits) {
      limits.timeoutSeconds *= timeFactor;
      return limits;
    };
    if (fuzzCase.target == Target::Cli) return runCliCase(fuzzCase, cli(), dir, scaled(cliLimits_));
    return runInChild([&] { return checkFileCase(fuzzCase, dir); }, scaled(limits_),
                      dir / "child.log");
  }

  const CliFixtures& cli() {
    if (!cli_)
      cli_ = prepareCliFixtures(settings_.chorus, settings_.source, work_ / "seeds",
                                work_ / "fixtures", cliLimits_);
    return *cli_;
  }

  const Settings& settings_;
  fs::path work_;
  SeedCorpus seeds_;
  std::optional<CliFixtures> cli_;
  ChildLimits limits_, cliLimits_;
};

std::string findingClass(const std::string& summary) {
  static const std::regex digits("[0-9]+");
  return std::regex_replace(summary.substr(0, 90), digits, "#");
}

void saveFinding(const Settings& settings, const FuzzCase& fuzzCase, const Outcome& outcome,
                 uint64_t index) {
  const fs::path dir =
      settings.out / std::string(targetName(fuzzCase.target)) / std::to_string(index);
  fs::remove_all(dir);
  writeCase(fuzzCase, dir, true);
  std::ofstream report(dir / "finding.txt");
  report << "target   " << targetName(fuzzCase.target) << "\nseed     " << settings.seed
         << "\ncase     " << index << "\noutcome  " << outcome.summary << "\nmutations\n";
  for (const std::string& m : fuzzCase.mutations) report << "  " << m << "\n";
  report << "reproduce\n  fuzz_inputs --target " << targetName(fuzzCase.target) << " --seed "
         << settings.seed << " --case " << index << "\n  fuzz_inputs --replay " << dir.string()
         << "\n";
  std::ofstream(dir / "stderr.txt") << outcome.log;
}

std::vector<Target> selectedTargets(const Settings& settings) {
  std::vector<Target> targets;
  for (const std::string& list : settings.targets) {
    std::stringstream s(list);
    for (std::string name; std::getline(s, name, ',');) {
      if (name == "all") {
        targets.assign(std::begin(kAllTargets), std::end(kAllTargets));
        continue;
      }
      const std::optional<Target> t = targetFromName(name);
      if (!t)
        throw Error("--target: unknown target '" + name + "' (gltf, exr, environment, cli, all)");
      if (std::find(targets.begin(), targets.end(), *t) == targets.end()) targets.push_back(*t);
    }
  }
  return targets;
}

void record(Tally& tally, const Outcome& outcome) {
  ++tally.verdicts[outcome.verdict];
  if (outcome.verdict == Verdict::Finding) ++tally.findingClasses[findingClass(outcome.summary)];
}

int fuzz(const Settings& settings) {
  const std::vector<Target> targets = selectedTargets(settings);
  Driver driver(settings);
  std::map<Target, Tally> tallies;
  const auto start = std::chrono::steady_clock::now();
  const auto elapsed = [&] {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  };
  const uint64_t first = settings.onlyCase.value_or(settings.first);
  const uint64_t end = settings.onlyCase ? first + 1 : settings.first + settings.count;
  uint64_t findings = 0;
  for (uint64_t i = first; i < end; ++i) {
    if (settings.seconds > 0 && elapsed() > settings.seconds) break;
    const Target target = targets[i % targets.size()];
    const double caseStart = elapsed();
    const FuzzCase fuzzCase = driver.generate(target, i);
    const Outcome outcome = driver.run(fuzzCase);
    Tally& tally = tallies[target];
    tally.seconds += elapsed() - caseStart;
    record(tally, outcome);
    if (settings.verbose || outcome.verdict == Verdict::Finding || settings.onlyCase) {
      std::printf("%s %llu: %s: %s\n", std::string(targetName(target)).c_str(),
                  (unsigned long long)i, std::string(verdictName(outcome.verdict)).c_str(),
                  outcome.summary.substr(0, 200).c_str());
      if (settings.onlyCase)
        for (const std::string& m : fuzzCase.mutations) std::printf("  %s\n", m.c_str());
      std::fflush(stdout);
    }
    if (outcome.verdict == Verdict::Finding) {
      ++findings;
      saveFinding(settings, fuzzCase, outcome, i);
    }
  }
  std::printf("\n%-12s %8s %8s %8s %6s %8s %9s\n", "target", "cases", "ok", "rejected", "slow",
              "findings", "seconds");
  Tally total;
  for (const auto& [target, t] : tallies) {
    std::printf("%-12s %8llu %8llu %8llu %6llu %8llu %9.1f\n",
                std::string(targetName(target)).c_str(), t.cases(), t.count(Verdict::Ok),
                t.count(Verdict::Rejected), t.count(Verdict::Slow), t.count(Verdict::Finding),
                t.seconds);
    for (const auto& [name, n] : t.findingClasses)
      total.findingClasses[std::string(targetName(target)) + ": " + name] += n;
  }
  std::printf("total %.1f s, %llu finding(s)%s\n", elapsed(), (unsigned long long)findings,
              findings ? (", saved under " + settings.out.string()).c_str() : "");
  for (const auto& [name, n] : total.findingClasses)
    std::printf("  %5llu  %s\n", (unsigned long long)n, name.c_str());
  return findings ? 1 : 0;
}

// Regression inputs and saved findings: a directory named after a target holds one case per
// entry; a case is a file or a directory inside such a directory.
void collectReplays(const fs::path& path, std::vector<std::pair<Target, fs::path>>& cases) {
  if (const auto t = targetFromName(path.filename().string()); t && fs::is_directory(path)) {
    std::vector<fs::path> entries;
    for (const auto& e : fs::directory_iterator(path)) entries.push_back(e.path());
    std::sort(entries.begin(), entries.end());
    for (const fs::path& e : entries) cases.emplace_back(*t, e);
    return;
  }
  if (const auto t = targetFromName(path.parent_path().filename().string())) {
    cases.emplace_back(*t, path);
    return;
  }
  if (!fs::is_directory(path))
    throw fileError(
        path,
        "not a regression input (expected under a directory named gltf, exr, environment or cli)");
  for (const Target t : kAllTargets)
    if (fs::is_directory(path / std::string(targetName(t))))
      collectReplays(path / std::string(targetName(t)), cases);
}

int replay(const Settings& settings) {
  std::vector<std::pair<Target, fs::path>> cases;
  for (const std::string& p : settings.replay)
    collectReplays(fs::path(p).lexically_normal(), cases);
  Driver driver(settings);
  int findings = 0;
  for (const auto& [target, path] : cases) {
    const Outcome outcome = driver.run(readCase(target, path));
    std::printf("%s: %s%s%s\n", path.string().c_str(),
                std::string(verdictName(outcome.verdict)).c_str(),
                outcome.summary.empty() ? "" : ": ", outcome.summary.substr(0, 300).c_str());
    if (outcome.verdict == Verdict::Finding) {
      ++findings;
      if (settings.verbose) std::printf("%s\n", outcome.log.c_str());
    }
  }
  return findings ? 1 : 0;
}

}  // namespace
}  // namespace chorus::fuzz

int main(int argc, char** argv) {
  using namespace chorus::fuzz;
  Settings s;
  CLI::App app{
      "fuzz_inputs: deterministic mutation fuzzing of chorus's scene loaders, EXR/HDR readers and "
      "CLI",
      "fuzz_inputs"};
  app.add_option("--target", s.targets, "gltf, exr, environment, cli or all (comma-separated)")
      ->delimiter(',');
  app.add_option("--seed", s.seed, "Seed of the run");
  app.add_option("--count", s.count, "Cases to generate (over all targets)");
  app.add_option("--seconds", s.seconds, "Start no new case after this many seconds (0: no limit)");
  app.add_option("--first", s.first, "Index of the first case (resumes a run)");
  app.add_option("--case", s.onlyCase, "Run only this case index (reproduces a finding)");
  app.add_option("--replay", s.replay,
                 "Replay regression inputs or saved findings instead of fuzzing");
  app.add_option("--out", s.out, "Where findings are saved");
  app.add_option("--work", s.work,
                 "Scratch directory (default: a temporary one, removed at the end)");
  app.add_option("--chorus", s.chorus, "The chorus binary for the CLI target");
  app.add_option("--source", s.source, "The chorus source tree (for scenes/)");
  app.add_option("--timeout", s.timeout, "Seconds before an in-process case counts as a hang");
  app.add_option("--cli-timeout", s.cliTimeout, "Seconds before a chorus run counts as a hang");
  app.add_option("--memory-mb", s.memoryMb, "Address-space limit of each case (0: none)");
  app.add_flag("--verbose", s.verbose, "Print every case");
  app.add_flag("--self-test", s.selfTest,
               "Check that the sandbox judges simulated crashes, hangs and errors");
  try {
    app.parse(argc, argv);
    if (s.selfTest) return runSelfTest();
    return s.replay.empty() ? fuzz(s) : replay(s);
  } catch (const CLI::ParseError& e) {
    app.exit(e);
    return e.get_exit_code() == 0 ? 0 : 2;
  } catch (const chorus::Error& e) {
    std::fprintf(stderr, "fuzz_inputs: %s\n", e.what());
    return 2;
  }
}
