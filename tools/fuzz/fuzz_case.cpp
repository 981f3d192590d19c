#include "tools/fuzz/fuzz_case.h"

#include <sys/stat.h>

#include <algorithm>
#include <fstream>
#include <sstream>

#include "common/atomic_file.h"
#include "common/error.h"

namespace chorus::fuzz {
namespace fs = std::filesystem;

namespace {
constexpr std::string_view kFifoSuffix = ".mkfifo";
constexpr std::string_view kArgsFile = "args.txt";

std::vector<std::string> lines(const std::string& text) {
  std::vector<std::string> result;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) result.push_back(line);
  return result;
}
}  // namespace

std::string_view targetName(Target target) {
  switch (target) {
    case Target::Gltf:
      return "gltf";
    case Target::Exr:
      return "exr";
    case Target::Environment:
      return "environment";
    case Target::Cli:
      return "cli";
  }
  return "?";
}

std::optional<Target> targetFromName(std::string_view name) {
  for (const Target t : kAllTargets)
    if (targetName(t) == name) return t;
  return std::nullopt;
}

std::string_view verdictName(Verdict verdict) {
  switch (verdict) {
    case Verdict::Ok:
      return "ok";
    case Verdict::Rejected:
      return "rejected";
    case Verdict::Slow:
      return "slow";
    case Verdict::Finding:
      return "FINDING";
  }
  return "?";
}

void writeCase(const FuzzCase& fuzzCase, const fs::path& dir, bool fifoMarkers) {
  fs::create_directories(dir);
  for (const CaseFile& file : fuzzCase.files) {
    fs::path path = dir / file.name;
    fs::create_directories(path.parent_path());
    if (file.fifo && fifoMarkers) path += kFifoSuffix;
    if (file.fifo && !fifoMarkers) {
      if (::mkfifo(path.c_str(), 0600) != 0) throw fileError(path, "cannot create a FIFO");
      continue;
    }
    std::ofstream out(path, std::ios::binary);
    out.write(file.bytes.data(), std::streamsize(file.bytes.size()));
    if (!out) throw fileError(path, "cannot write");
  }
  if (!fuzzCase.args.empty()) {
    std::ofstream out(dir / kArgsFile);
    for (const std::string& arg : fuzzCase.args) out << arg << "\n";
  }
}

FuzzCase readCase(Target target, const fs::path& path) {
  FuzzCase result;
  result.target = target;
  if (fs::is_regular_file(path)) {
    if (path.filename() == kArgsFile) {
      result.args = lines(readFileBytes(path));
    } else {
      result.files.push_back({path.filename().string(), readFileBytes(path)});
    }
    return result;
  }
  if (!fs::is_directory(path)) throw fileError(path, "no such regression input");
  std::vector<fs::path> entries;
  for (const auto& entry : fs::recursive_directory_iterator(path))
    if (entry.is_regular_file()) entries.push_back(entry.path());
  std::sort(entries.begin(), entries.end());
  for (const fs::path& file : entries) {
    const std::string name = fs::relative(file, path).string();
    if (name == "finding.txt" || name == "stderr.txt") continue;
    if (name == kArgsFile) {
      result.args = lines(readFileBytes(file));
    } else if (name.ends_with(kFifoSuffix)) {
      result.files.push_back({name.substr(0, name.size() - kFifoSuffix.size()), "", true});
    } else {
      result.files.push_back({name, readFileBytes(file)});
    }
  }
  return result;
}

}  // namespace chorus::fuzz
