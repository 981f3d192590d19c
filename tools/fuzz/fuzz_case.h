#pragma once
// One fuzz input and its outcome. A case is a set of files (and, for the CLI, an argument
// vector) written into its own directory; the same layout is what findings are saved as and
// what tests/fuzz/<target>/ holds, so every saved or regression input replays through the same
// code (replayCase in fuzz_targets.h).
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace chorus::fuzz {

enum class Target { Gltf, Exr, Environment, Cli };
inline constexpr Target kAllTargets[] = {Target::Gltf, Target::Exr, Target::Environment,
                                         Target::Cli};
std::string_view targetName(Target target);  // "gltf", "exr", "environment", "cli"
std::optional<Target> targetFromName(std::string_view name);

struct CaseFile {
  std::string name;  // relative to the case directory
  std::string bytes;
  bool fifo = false;  // created as a named pipe (a regression input stores it as NAME.mkfifo)
};

struct FuzzCase {
  Target target = Target::Gltf;
  std::vector<CaseFile> files;
  // cli: chorus's arguments; "{case}" stands for the case directory, "{fixtures}" for the
  // directory of valid inputs the driver prepares (fuzz_cli.h). Stored as args.txt, one a line.
  std::vector<std::string> args;
  std::vector<std::string> mutations;  // what was changed, one line each (for the report)
};

// Ok: loaded or ran. Rejected: chorus::Error, or exit 2 (the message is the summary). Slow: a
// CLI run that timed out while asking for a huge amount of valid work (--spp 2^31). Finding:
// everything else (crash, hang, sanitizer report, other exception, exit 1, broken promise).
enum class Verdict { Ok, Rejected, Slow, Finding };
std::string_view verdictName(Verdict verdict);

struct Outcome {
  Verdict verdict = Verdict::Ok;
  std::string summary;  // one line
  std::string log;      // what the child printed on stderr (findings only)
  bool timedOut = false;
};

// Writes the case's files (and args.txt) into `dir`, creating it. FIFOs are created as such to
// run the case, or as empty NAME.mkfifo markers to save it (`fifoMarkers`).
void writeCase(const FuzzCase& fuzzCase, const std::filesystem::path& dir,
               bool fifoMarkers = false);
// Reads a case back: a directory (every file in it; NAME.mkfifo becomes a FIFO named NAME;
// finding.txt and stderr.txt are ignored) or a single file. Throws chorus::Error.
FuzzCase readCase(Target target, const std::filesystem::path& path);

}  // namespace chorus::fuzz
