#include "tools/fuzz/self_test.h"

#include <unistd.h>

#include <csignal>
#include <cstdio>
#include <functional>
#include <new>
#include <string>

#include "common/error.h"
#include "tools/fuzz/sandbox.h"

namespace chorus::fuzz {
namespace {
namespace fs = std::filesystem;

struct Check {
  const char* name;
  std::function<std::string()> body;
  Verdict expected;
  const char* summaryStart;
};

}  // namespace

int runSelfTest() {
  const fs::path dir =
      fs::temp_directory_path() / ("chorus-fuzz-self-test-" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const ChildLimits limits{1.0, size_t(1) << 30};
  const Check checks[] = {
      {"handled", [] { return std::string(); }, Verdict::Ok, ""},
      {"chorus::Error", []() -> std::string { throw Error("bad input"); }, Verdict::Rejected,
       "bad input"},
      {"broken promise", [] { return std::string("index out of range"); }, Verdict::Finding,
       "index out of range"},
      {"std::bad_alloc", []() -> std::string { throw std::bad_alloc(); }, Verdict::Finding,
       "uncaught std::bad_alloc"},
      // AddressSanitizer reports a SIGSEGV itself and exits with code 1.
      {"SIGSEGV",
       []() -> std::string {
         std::raise(SIGSEGV);
         return "";
       },
       Verdict::Finding, sanitizerBuild() ? "exit code 1" : "crash: SIGSEGV"},
      {"abort", []() -> std::string { std::abort(); }, Verdict::Finding, "crash: SIGABRT"},
      {"hang",
       []() -> std::string {
         for (;;) ::pause();
       },
       Verdict::Finding, "hang"},
      {"exit 3", []() -> std::string { ::_exit(3); }, Verdict::Finding, "exit code 3"},
  };
  int wrong = 0;
  for (const Check& check : checks) {
    const Outcome outcome = runInChild(check.body, limits, dir / "child.log");
    const bool right =
        outcome.verdict == check.expected && outcome.summary.starts_with(check.summaryStart);
    wrong += !right;
    std::printf("%s %s: %s %s\n", right ? "ok   " : "WRONG", check.name,
                std::string(verdictName(outcome.verdict)).c_str(), outcome.summary.c_str());
  }
  const ProcessResult sleeper = runProcess({"/bin/sleep", "30"}, limits, dir, dir);
  wrong += !sleeper.timedOut;
  std::printf("%s child process past its timeout: %s\n", sleeper.timedOut ? "ok   " : "WRONG",
              sleeper.timedOut ? "killed" : "not noticed");
  const ProcessResult exits =
      runProcess({"/bin/sh", "-c", "echo out; echo err >&2; exit 2"}, limits, dir, dir);
  const bool captured = exits.exitCode == 2 && exits.out == "out\n" && exits.err == "err\n";
  wrong += !captured;
  std::printf("%s child process exit code and output: %d\n", captured ? "ok   " : "WRONG",
              exits.exitCode);
  std::error_code ec;
  fs::remove_all(dir, ec);
  return wrong ? 1 : 0;
}

}  // namespace chorus::fuzz
