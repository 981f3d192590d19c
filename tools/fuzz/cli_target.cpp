#include "tools/fuzz/cli_target.h"

#include <sys/stat.h>

#include <cctype>
#include <cmath>
#include <fstream>
#include <limits>
#include <map>
#include <regex>
#include <sstream>

#include "common/atomic_file.h"
#include "common/error.h"
#include "common/image/exr_io.h"
#include "tools/sweep/sweep_runner.h"

namespace chorus::fuzz {
namespace fs = std::filesystem;

namespace {

const std::string kF = "{fixtures}/";

// ---- value pools -----------------------------------------------------------------------------

const std::vector<std::string> kIntegers = {"-1",
                                            "0",
                                            "1",
                                            "2",
                                            "3",
                                            "7",
                                            "2147483647",
                                            "2147483648",
                                            "-2147483648",
                                            "4294967296",
                                            "9223372036854775807",
                                            "18446744073709551616",
                                            "1e9",
                                            "1e23",
                                            "1e309",
                                            "nan",
                                            "inf",
                                            "-inf",
                                            "",
                                            "abc",
                                            "0x10",
                                            "1.5",
                                            " 4",
                                            "100000",
                                            "65536",
                                            "1000000",
                                            "-0"};
const std::vector<std::string> kFloats = {"-1",     "0",   "-0",   "1e-30",      "1e-320", "0.5",
                                          "1",      "4",   "1e20", "1e38",       "3.5e38", "1e309",
                                          "-1e309", "nan", "-nan", "inf",        "-inf",   "",
                                          "abc",    "1,2", "1e",   "2147483647", "1e-45"};
const std::vector<std::string> kTexts = {
    "", "nan", ",", ",,", "none", "x", std::string(5000, 'a'), "-1", "1e309", "inf", "default"};
const std::vector<std::string> kScenes = {kF + "scene.gltf",
                                          kF + "scene.gltf",
                                          kF + "triangle.gltf",
                                          kF + "missing.gltf",
                                          kF + "emptydir",
                                          kF + "text.txt",
                                          kF + "render/render.exr",
                                          kF + "broken.gltf",
                                          "",
                                          "/dev/null",
                                          "/dev/zero",
                                          kF + "fifo"};
const std::vector<std::string> kImages = {kF + "render/render.exr",
                                          kF + "reference/render.exr",
                                          kF + "nan.exr",
                                          kF + "allnan.exr",
                                          kF + "inf.exr",
                                          kF + "small.exr",
                                          kF + "tungsten",
                                          kF + "missing.exr",
                                          kF + "emptydir",
                                          kF + "text.txt",
                                          kF + "scene.gltf",
                                          "",
                                          "/dev/null"};
const std::vector<std::string> kEnvironments = {
    kF + "env.hdr",  kF + "sky.exr",  kF + "nan.exr",    kF + "allnan.exr", kF + "missing.hdr",
    kF + "text.txt", kF + "emptydir", kF + "scene.gltf", kF + "small.exr"};
// Never an absolute system path: chorus may write there (the fuzzer may run as root).
const std::vector<std::string> kOutputs = {"{case}/out",  "{case}/out/a/b", "",   ".",
                                           "{case}/file", "{case}/out/",    "out"};
const std::map<std::string, std::vector<std::string>> kDenoiserKeys = {
    {"atrous",
     {"iterations", "sigmaL", "sigmaN", "sigmaZ", "demodulate", "clampFireflies", "symmetricFrom",
      "borrow"}},
    {"nfor", {"regressionR", "finalR", "finalK", "epsilon", "mseR", "prefilterK"}},
    {"nlm", {"r", "f", "k", "alpha", "weightThreshold"}},
    {"sbf", {"sigmaS", "sigmaR", "sigmaN", "sigmaMse"}},
    {"bilateral", {"sigmaS", "sigmaC", "sigmaD", "sigmaN"}},
    {"rdfc", {"r", "kc", "kf", "tau", "selectionR", "fFirst"}},
    {"jnlm", {"r", "f", "k", "kf", "tau", "alpha"}},
    {"bogus", {"x"}}};
const std::vector<std::string> kCombiners = {"ensemble",    "average", "onehot-pre",
                                             "onehot-post", "oracle",  "oracle-unconstrained",
                                             "bogus",       ""};

// Flags whose huge values legitimately ask for hours of work (a timeout there is Slow), and
// flags naming files or directories rather than values.
bool isWorkFlag(const std::string& flag) {
  return flag != "--seed" && flag != "--solver-seed" && flag != "--threads" && flag != "--camera" &&
         flag != "--shard";
}
bool isPathFlag(const std::string& flag) {
  return flag == "--out" || flag == "--env" || flag == "--reference" || flag == "--merge";
}

std::string denoiserSpec(FuzzRandom& rng) {
  std::vector<std::string> names;
  for (const auto& [name, keys] : kDenoiserKeys) names.push_back(name);
  std::string spec = rng.pick(names);
  const size_t params = rng.below(3);
  for (size_t i = 0; i < params; ++i) {
    spec += (i == 0 ? ":" : ":") + rng.pick(kDenoiserKeys.at(spec.substr(0, spec.find(':')))) +
            "=" + (rng.chance(0.5) ? rng.pick(kIntegers) : rng.pick(kFloats));
  }
  if (rng.chance(0.05)) spec += rng.pick(std::vector<std::string>{":", "=", ":=", ":x"});
  return spec;
}

std::string list(FuzzRandom& rng, const std::function<std::string()>& item) {
  std::string text = item();
  const size_t more = rng.below(3);
  for (size_t i = 0; i < more; ++i) text.append(",").append(item());
  if (rng.chance(0.05)) text += ",";
  return text;
}

std::string valueFor(const CliFlag& flag, FuzzRandom& rng) {
  const std::string& n = flag.name;
  if (n == "--out") return rng.pick(kOutputs);
  if (n == "--env") return rng.pick(kEnvironments);
  if (n == "--reference") return rng.pick(kImages);
  if (n == "--merge")
    return rng.pick(std::vector<std::string>{kF + "emptydir", kF + "missing", "{case}/out", ""});
  if (n == "--denoise" || n == "--methods")
    return rng.chance(0.15)
               ? rng.pick(std::vector<std::string>{"none", "default", "preview", "", ","})
               : list(rng, [&] { return denoiserSpec(rng); });
  if (n == "--combine" || n == "--combiners")
    return list(rng, [&] { return rng.pick(kCombiners); });
  if (n == "--combos")
    return rng.pick(std::vector<std::string>{"all", "none", "nfor+rdfc", "atrous+atrous", "+",
                                             "x+y", "atrous+bilateral,nfor+x", ""});
  if (n == "--shard")
    return rng.pick(std::vector<std::string>{"0/0", "1/0", "-1/2", "5/2", "0/2147483648", "a/b",
                                             "0/1/2", "1/2", "0/18446744073709551616"});
  if (n == "--background")
    return rng.pick(std::vector<std::string>{"1,2,3", "nan", "1e309", "-1", "1,2", "1,2,3,4",
                                             "inf,0,0", "0.5", "", "a,b,c", "1e38,1e38,1e38"});
  if (n == "--layer")
    return rng.pick(std::vector<std::string>{"", "albedo", "sub0.color", "nope", "colorVariance",
                                             "depth", "normal"});
  if (flag.type == "TEXT" && n == "--spp") return list(rng, [&] { return rng.pick(kIntegers); });
  if (!flag.choices.empty() && rng.chance(0.5)) return rng.pick(flag.choices);
  if (flag.type == "INT" || flag.type == "UINT") return rng.pick(kIntegers);
  if (flag.type == "FLOAT") return rng.pick(kFloats);
  return rng.pick(kTexts);
}

// ---- fixtures --------------------------------------------------------------------------------

std::vector<std::string> subcommands(const std::string& help) {
  std::vector<std::string> names;
  std::istringstream in(help.substr(std::min(help.size(), help.find("Subcommands:"))));
  std::string line;
  std::getline(in, line);
  static const std::regex entry(R"(^  ([a-z][a-z0-9-]*)\s)");
  std::smatch m;
  while (std::getline(in, line))
    if (std::regex_search(line, m, entry)) names.push_back(m[1]);
  return names;
}

std::vector<std::string> baseArguments(const std::string& command) {
  const std::string scene = kF + "scene.gltf", render = kF + "render/render.exr";
  if (command == "render")
    return {"render", scene, "--out",     "{case}/out", "--width", "8",         "--height", "8",
            "--spp",  "2",   "--threads", "1",          "--quiet", "--denoise", "atrous"};
  if (command == "denoise")
    return {"denoise", render, "--methods", "atrous", "--out", "{case}/out"};
  if (command == "compare") return {"compare", render, kF + "reference/render.exr"};
  if (command == "info") return {"info", scene};
  if (command == "sweep")
    return {"sweep",           scene,  "--out",       "{case}/out",
            "--spp",           "2",    "--width",     "8",
            "--height",        "8",    "--methods",   "atrous,bilateral",
            "--combos",        "none", "--combiners", "ensemble,average",
            "--reference-spp", "8",    "--threads",   "1",
            "--quiet"};
  return {command};
}

void writeImages(const fs::path& dir) {
  Image image(8, 8, 3, 0.5f);
  writeExr(dir / "small.exr", Image(4, 4, 3, 0.5f));
  image(3, 2, 1) = std::nanf("");
  writeExr(dir / "nan.exr", image);
  image(3, 2, 1) = INFINITY;
  writeExr(dir / "inf.exr", image);
  writeExr(dir / "allnan.exr", Image(8, 8, 3, std::nanf("")));
}

// ---- judging ---------------------------------------------------------------------------------

std::string substitute(std::string arg, const fs::path& fixtures, const fs::path& caseDir) {
  for (const auto& [name, value] :
       {std::pair<std::string, std::string>{"{fixtures}", fixtures.string()},
        std::pair<std::string, std::string>{"{case}", caseDir.string()}})
    for (size_t at = arg.find(name); at != std::string::npos;
         at = arg.find(name, at + value.size()))
      arg.replace(at, name.size(), value);
  return arg;
}

// The value given to each flag (for "--x v" and "--x=v"), in order.
std::vector<std::pair<std::string, std::string>> flagValues(const std::vector<std::string>& args) {
  std::vector<std::pair<std::string, std::string>> values;
  for (size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    if (!a.starts_with("--")) continue;
    if (const size_t eq = a.find('='); eq != std::string::npos)
      values.emplace_back(a.substr(0, eq), a.substr(eq + 1));
    else if (i + 1 < args.size() && !args[i + 1].starts_with("--"))
      values.emplace_back(a, args[i + 1]);
  }
  return values;
}

bool mentionsNan(const std::string& value) {
  static const std::regex nan(R"((^|[=,:+])-?nan($|[,:]))", std::regex::icase);
  return std::regex_search(value, nan);
}

// Whether `value` is a number of the flag's type within its range: an integer that fits (INT:
// 32-bit signed, UINT: 64-bit unsigned) or a finite FLOAT. TEXT and switches always are.
bool inRange(const std::string& type, std::string value) {
  if (type != "INT" && type != "UINT" && type != "FLOAT") return true;
  while (!value.empty() && std::isspace(static_cast<unsigned char>(value.front())))
    value.erase(0, 1);
  while (!value.empty() && std::isspace(static_cast<unsigned char>(value.back()))) value.pop_back();
  if (value.empty()) return false;
  char* end = nullptr;
  const long double v = std::strtold(value.c_str(), &end);
  if (*end != '\0' || !std::isfinite(v)) return false;
  if (type == "FLOAT") return std::fabs(v) <= std::numeric_limits<double>::max();
  if (v != std::floor(v)) return false;
  return type == "INT" ? v >= -2147483648.0L && v <= 2147483647.0L
                       : v >= 0 && v <= 18446744073709551615.0L;
}

bool asksForHugeWork(const std::vector<std::string>& args) {
  static const std::regex number(R"([-+]?[0-9.]+(e[+-]?[0-9]+)?)", std::regex::icase);
  // A sweep renders its references at 16384 spp unless told otherwise: an 8 × 65536 sweep is
  // 8.6e9 reference samples without any value of 1e5.
  double width = 0, height = 0;
  bool referenceSet = false;
  const auto values = flagValues(args);
  for (const auto& [flag, value] : values) {
    if (flag == "--width") width = std::strtod(value.c_str(), nullptr);
    if (flag == "--height") height = std::strtod(value.c_str(), nullptr);
    referenceSet = referenceSet || flag == "--reference-spp" || flag == "--reference-seconds";
  }
  if (!args.empty() && args[0] == "sweep" && !referenceSet &&
      width * height * sweep::kDefaultReferenceSpp >= 1e9)
    return true;
  for (const auto& [flag, value] : values) {
    if (!isWorkFlag(flag)) continue;
    for (auto it = std::sregex_iterator(value.begin(), value.end(), number);
         it != std::sregex_iterator(); ++it) {
      const double v = std::strtod(it->str().c_str(), nullptr);
      if (std::isfinite(v) && v >= 1e5) return true;
    }
  }
  return false;
}

// What chorus printed on stderr but its warnings, CLI11's hint and the subcommand's progress
// lines ("sweep: 1 case(s) in this shard, …" before the error).
std::vector<std::string> errorLines(const std::string& err, const std::string& command) {
  std::vector<std::string> lines;
  std::istringstream in(err);
  for (std::string line; std::getline(in, line);) {
    if (line.empty() || line.starts_with("chorus: warning:") ||
        line == "Run with --help for more information." ||
        (!command.empty() && line.starts_with(command + ": ")))
      continue;
    lines.push_back(line);
  }
  return lines;
}

// The length of an error line without the arguments it quotes (echoing a 5000-character value
// back is fine; printing DBL_MAX with 309 digits is not).
size_t ownLength(std::string line, const std::vector<std::string>& args) {
  for (std::string arg : args) {
    if (arg.starts_with("--") && arg.find('=') != std::string::npos)
      arg.erase(0, arg.find('=') + 1);  // --flag=value quotes the value
    if (arg.size() >= 20)
      for (size_t at = line.find(arg); at != std::string::npos; at = line.find(arg, at))
        line.erase(at, arg.size());
  }
  return line.size();
}

// The type of `flag` in `command`'s --help ("" for a switch or an unknown flag).
std::string flagType(const CliFixtures& fixtures, const std::string& command,
                     const std::string& flag) {
  for (const CliCommand& c : fixtures.commands)
    if (c.name == command)
      for (const CliFlag& f : c.flags)
        if (f.name == flag) return f.type;
  return "";
}

std::vector<fs::path> filesUnder(const fs::path& dir) {
  std::vector<fs::path> files;
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) return files;
  for (auto it = fs::recursive_directory_iterator(dir, ec);
       !ec && it != fs::recursive_directory_iterator(); it.increment(ec))
    if (it->is_regular_file(ec)) files.push_back(it->path());
  return files;
}

// Reads every EXR under `dir` in a sandboxed child (the parent must not start OpenEXR's pool).
Outcome checkWrittenImages(const fs::path& dir, const ChildLimits& limits, const fs::path& log) {
  return runInChild(
      [&]() -> std::string {
        for (const fs::path& file : filesUnder(dir)) {
          if (file.extension() != ".exr") continue;
          for (const ExrLayer& layer : readExr(file))
            for (const float v : layer.image.values())
              if (!std::isfinite(v))
                return "exit 0 but " + fs::relative(file, dir).string() + " layer '" + layer.name +
                       "' holds a non-finite value";
        }
        return "";
      },
      limits, log);
}

std::string firstLine(const std::string& text) {
  return text.substr(0, std::min(text.find('\n'), size_t(200)));
}

}  // namespace

std::vector<CliFlag> parseHelpFlags(const std::string& help) {
  std::vector<CliFlag> flags;
  static const std::regex option(
      R"(^  (?:-\w,)?(--[\w-]+)(?:,--[\w-]+)*(?:\{[^}]*\})?(?: ([A-Z]+)(?::\{([^}]*)\})?)?)");
  std::istringstream in(help);
  std::smatch m;
  for (std::string line; std::getline(in, line);) {
    if (!std::regex_search(line, m, option) || m[1] == "--help") continue;
    CliFlag flag{m[1], m[2], {}};
    std::istringstream choices(m[3]);
    for (std::string c; std::getline(choices, c, ',');) flag.choices.push_back(c);
    flags.push_back(flag);
  }
  return flags;
}

CliFixtures prepareCliFixtures(const fs::path& chorus, const fs::path& sourceDir,
                               const fs::path& seedDir, const fs::path& dir,
                               const ChildLimits& limits) {
  if (!fs::is_regular_file(chorus))
    throw fileError(chorus, "no chorus binary to fuzz (build it, or pass --chorus)");
  fs::remove_all(dir);
  fs::create_directories(dir / "emptydir");
  CliFixtures fixtures{chorus, dir, {}};
  const fs::path scenes = sourceDir / "scenes";
  fs::copy_file(scenes / "cornell-box.gltf", dir / "scene.gltf");
  fs::copy_file(scenes / "cornell-box.bin", dir / "cornell-box.bin");
  const std::string cornell = readFileBytes(scenes / "cornell-box.gltf");
  writeTextAtomically(dir / "broken.gltf", cornell.substr(0, cornell.size() / 2));
  writeTextAtomically(dir / "text.txt", "not a scene\n");
  fs::copy_file(seedDir / "gltf" / "triangle.gltf", dir / "triangle.gltf");
  fs::copy_file(seedDir / "environment" / "rle.hdr", dir / "env.hdr");
  fs::copy_file(seedDir / "environment" / "sky.exr", dir / "sky.exr");
  fs::copy(seedDir / "exr" / "tungsten", dir / "tungsten");
  if (::mkfifo((dir / "fifo").c_str(), 0600) != 0)
    throw fileError(dir / "fifo", "cannot create a FIFO");
  const Outcome images = runInChild(
      [&] {
        writeImages(dir);
        return std::string();
      },
      limits, dir / "images.log");
  if (images.verdict != Verdict::Ok)
    throw Error("fuzz: cannot write the CLI fixtures: " + images.summary);

  ChildLimits slow = limits;
  slow.timeoutSeconds = std::max(limits.timeoutSeconds, 120.0);
  // A K = 4 render.exr, and a second, independent one as the reference of comparisons.
  for (const auto& [name, seed] : {std::pair{"render", "0"}, std::pair{"reference", "1"}}) {
    const ProcessResult rendered = runProcess({chorus.string(),
                                               "render",
                                               (dir / "scene.gltf").string(),
                                               "--out",
                                               (dir / name).string(),
                                               "--width",
                                               "8",
                                               "--height",
                                               "8",
                                               "--spp",
                                               "4",
                                               "--splits",
                                               "4",
                                               "--denoise",
                                               "none",
                                               "--seed",
                                               seed,
                                               "--threads",
                                               "1",
                                               "--quiet"},
                                              slow, dir / "capture", dir);
    if (rendered.exitCode != 0 || !fs::is_regular_file(dir / name / "render.exr"))
      throw Error("fuzz: chorus could not render the CLI fixture: " + firstLine(rendered.err));
  }

  const ProcessResult top = runProcess({chorus.string(), "--help"}, slow, dir / "capture", dir);
  for (const std::string& name : subcommands(top.out)) {
    const ProcessResult help =
        runProcess({chorus.string(), name, "--help"}, slow, dir / "capture", dir);
    fixtures.commands.push_back({name, baseArguments(name), parseHelpFlags(help.out)});
  }
  if (fixtures.commands.empty()) throw Error("fuzz: `chorus --help` lists no subcommands");
  return fixtures;
}

FuzzCase generateCliCase(const CliFixtures& fixtures, FuzzRandom& rng) {
  FuzzCase fuzzCase;
  fuzzCase.target = Target::Cli;
  fuzzCase.files.push_back({"file", "a regular file where a directory belongs\n"});
  const CliCommand& command = rng.pick(fixtures.commands);
  std::vector<std::string>& args = fuzzCase.args;
  args = command.base;
  fuzzCase.mutations.push_back("base: chorus " + command.name);
  const auto findFlag = [&](const std::string& name) {
    return std::find(args.begin(), args.end(), name);
  };
  const int edits = int(1 + rng.below(3));
  for (int e = 0; e < edits; ++e) {
    const size_t op = rng.below(12);
    if (op <= 5 && !command.flags.empty()) {
      const CliFlag& flag = rng.pick(command.flags);
      const bool switchFlag = flag.type.empty();
      const std::string value = switchFlag ? "" : valueFor(flag, rng);
      const auto at = findFlag(flag.name);
      if (op == 5 || (switchFlag && rng.chance(0.3))) {
        const std::string v =
            switchFlag ? rng.pick(std::vector<std::string>{"true", "false", "nan", ""}) : value;
        args.push_back(flag.name + "=" + v);
        fuzzCase.mutations.push_back(flag.name + "=" + v.substr(0, 60));
      } else if (at != args.end() && !switchFlag && at + 1 != args.end()) {
        *(at + 1) = value;
        fuzzCase.mutations.push_back(flag.name + " " + value.substr(0, 60));
      } else {
        args.push_back(flag.name);
        if (!switchFlag) args.push_back(value);
        fuzzCase.mutations.push_back("add " + flag.name + " " + value.substr(0, 60));
      }
    } else if (op == 6 && args.size() > 2) {
      const size_t i = 1 + rng.below(args.size() - 1);
      const bool withValue =
          args[i].starts_with("--") && i + 1 < args.size() && !args[i + 1].starts_with("--");
      fuzzCase.mutations.push_back("remove " + args[i]);
      args.erase(args.begin() + std::ptrdiff_t(i),
                 args.begin() + std::ptrdiff_t(i + (withValue ? 2 : 1)));
    } else if (op <= 8 && args.size() > 1 && !args[1].starts_with("--")) {
      const bool images = command.name == "denoise" || command.name == "compare";
      const size_t i = command.name == "compare" && args.size() > 2 && !args[2].starts_with("--") &&
                               rng.chance(0.5)
                           ? 2
                           : 1;
      args[i] = rng.pick(images ? kImages : kScenes);
      fuzzCase.mutations.push_back("positional " + std::to_string(i) + " = '" + args[i] + "'");
    } else if (op == 9 && !command.flags.empty()) {
      const CliFlag& flag = rng.pick(command.flags);
      args.push_back(flag.name);
      if (!flag.type.empty()) args.push_back(valueFor(flag, rng));
      fuzzCase.mutations.push_back("repeat " + flag.name);
    } else if (op == 10 && !command.flags.empty()) {
      const CliFlag& flag = rng.pick(command.flags);
      args.push_back(flag.name);
      fuzzCase.mutations.push_back(flag.name + " without a value");
    } else {
      const std::string extra =
          rng.pick(std::vector<std::string>{"--bogus", "-x", "--", "extra", "-", "--=1"});
      args.insert(args.begin() + std::ptrdiff_t(1 + rng.below(args.size())), extra);
      fuzzCase.mutations.push_back("insert '" + extra + "'");
    }
  }
  return fuzzCase;
}

Outcome runCliCase(const FuzzCase& fuzzCase, const CliFixtures& fixtures, const fs::path& caseDir,
                   const ChildLimits& limits) {
  std::vector<std::string> argv = {fixtures.chorus.string()};
  for (const std::string& arg : fuzzCase.args)
    argv.push_back(substitute(arg, fixtures.dir, caseDir));
  const ProcessResult run = runProcess(argv, limits, caseDir / "capture", caseDir);
  const fs::path out = caseDir / "out";
  Outcome outcome;
  outcome.verdict = Verdict::Finding;
  outcome.log = run.err.substr(0, 6000);
  const auto values = flagValues(fuzzCase.args);
  if (run.timedOut) {
    if (asksForHugeWork(fuzzCase.args))
      return {Verdict::Slow, "timeout on a huge amount of valid work", ""};
    outcome.timedOut = true;
    outcome.summary = "hang: no exit after " + std::to_string(int(limits.timeoutSeconds)) + " s";
    return outcome;
  }
  if (run.signal) {
    outcome.summary = "crash: " + signalName(run.signal);
    if (const std::string s = sanitizerSummary(run.err); !s.empty())
      outcome.summary += " (" + s + ")";
    return outcome;
  }
  const std::string command = fuzzCase.args.empty() ? "" : fuzzCase.args[0];
  const std::vector<std::string> errors = errorLines(run.err, command);
  if (run.exitCode == 2) {
    if (errors.size() != 1) {
      outcome.summary = "exit 2 with " + std::to_string(errors.size()) + " error lines";
    } else if (const size_t length = ownLength(errors[0], argv); length > 300) {
      outcome.summary = "exit 2 with an error line of " + std::to_string(length) + " characters";
    } else if (const auto left = filesUnder(out); !left.empty()) {
      outcome.summary = "exit 2 left " + fs::relative(left[0], caseDir).string() + " in --out";
    } else {
      return {Verdict::Rejected, errors[0], ""};
    }
    return outcome;
  }
  if (run.exitCode != 0) {
    outcome.summary = "exit " + std::to_string(run.exitCode) + ": " +
                      (errors.empty() ? "" : firstLine(errors[0]));
    if (const std::string s = sanitizerSummary(run.err); !s.empty())
      outcome.summary += " (" + s + ")";
    return outcome;
  }
  for (const auto& [flag, value] : values) {
    if (!isPathFlag(flag) && !flagType(fixtures, command, flag).empty() && mentionsNan(value)) {
      outcome.summary = "exit 0 with " + flag + " " + value.substr(0, 60);
      return outcome;
    }
    if (const std::string type = flagType(fixtures, command, flag); !inRange(type, value)) {
      outcome.summary =
          "exit 0 with the out-of-range " + type + " " + flag + " '" + value.substr(0, 60) + "'";
      return outcome;
    }
    if (flag == "--out" && value.empty()) {
      outcome.summary = "exit 0 with an empty --out";
      return outcome;
    }
  }
  // "inf" alone is no finding: the PSNR of an image against itself is infinite, which --json
  // writes as "psnr": null (JSON has no infinity) beside an MSE of 0.
  static const std::regex nonFinite(R"(\b(nan|null)\b)", std::regex::icase);
  static const std::regex identicalPsnr(R"re("mse": 0(\.0)?,([^}]*)"psnr": null)re");
  if (command == "compare" &&
      std::regex_search(std::regex_replace(run.out, identicalPsnr, "$2"), nonFinite)) {
    outcome.summary = "exit 0 but compare printed a non-finite metric";
    return outcome;
  }
  for (const fs::path& file : filesUnder(out)) {
    if (file.extension() == ".csv" && std::regex_search(readFileBytes(file), nonFinite)) {
      outcome.summary =
          "exit 0 but " + fs::relative(file, caseDir).string() + " holds non-finite values";
      return outcome;
    }
  }
  Outcome images = checkWrittenImages(out, limits, caseDir / "check.log");
  if (images.verdict == Verdict::Ok) return {};
  images.verdict = Verdict::Finding;
  return images;
}

}  // namespace chorus::fuzz
