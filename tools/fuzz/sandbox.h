#pragma once
// Running one fuzz case without letting it take the driver down: every case runs in a forked
// child (in-process targets) or a child process (the CLI) with a wall-clock timeout, an
// address-space limit and no core dumps. The driver itself never starts threads (no TBB, no
// OpenEXR pool), so forking it is safe.
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "tools/fuzz/fuzz_case.h"

namespace chorus::fuzz {

struct ChildLimits {
  double timeoutSeconds = 10;
  // RLIMIT_AS of the child (0: none). Not applied in sanitizer builds, whose shadow memory needs
  // terabytes of address space; there the allocator's own limits apply (sanitizer_options.cpp).
  size_t memoryBytes = size_t(6) << 30;
};

// The options a sanitized child runs with (the driver's own, via sanitizer_options.cpp, and
// chorus's, via ASAN_OPTIONS; a user's ASAN_OPTIONS take precedence): a huge allocation fails
// as std::bad_alloc instead of exhausting the machine, leaks are not this harness's business,
// and a report ends the process with exit code 1.
inline constexpr const char* kAsanOptions =
    "allocator_may_return_null=1:max_allocation_size_mb=4096:detect_leaks=0";

// True when this program was built with AddressSanitizer (-DCHORUS_ASAN=ON).
bool sanitizerBuild();

// Runs `body` in a forked child, its stdout and stderr going to `logFile`. body returns "" when
// the input was handled, or a description of a broken promise (a finding). chorus::Error →
// Rejected; any other exception, a signal, a sanitizer report (non-zero exit without a result)
// or the timeout → Finding, with the log's sanitizer summary.
Outcome runInChild(const std::function<std::string()>& body, const ChildLimits& limits,
                   const std::filesystem::path& logFile);

struct ProcessResult {
  int exitCode = -1;  // when it exited
  int signal = 0;     // when a signal ended it
  bool timedOut = false;
  std::string out, err;
};

// Runs `argv` (argv[0] a path) in `workDir`, its stdout and stderr captured in files under
// `captureDir`.
ProcessResult runProcess(const std::vector<std::string>& argv, const ChildLimits& limits,
                         const std::filesystem::path& captureDir,
                         const std::filesystem::path& workDir);

// "SIGSEGV" etc.
std::string signalName(int signal);
// The most telling line of a sanitizer or crash log (its SUMMARY line, or the first runtime
// error), or "" when there is none.
std::string sanitizerSummary(const std::string& log);

}  // namespace chorus::fuzz
