#include "tools/fuzz/sandbox.h"

#include <cxxabi.h>
#include <fcntl.h>
#include <poll.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <csignal>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <memory>
#include <sstream>
#include <typeinfo>

#include "common/error.h"

namespace chorus::fuzz {
namespace fs = std::filesystem;

namespace {

// What runInChild's child writes to the pipe before it exits: one code byte, then the text.
constexpr char kHandled = 'O', kBrokenPromise = 'F', kChorusError = 'R', kOtherException = 'E';

constexpr const char* kUbsanOptions = "print_stacktrace=1";

void applyLimits(const ChildLimits& limits) {
  const rlimit noCore{0, 0};
  ::setrlimit(RLIMIT_CORE, &noCore);
  if (limits.memoryBytes > 0 && !sanitizerBuild()) {
    const rlimit memory{limits.memoryBytes, limits.memoryBytes};
    ::setrlimit(RLIMIT_AS, &memory);
  }
}

void writeAll(int fd, const std::string& text) {
  size_t done = 0;
  while (done < text.size()) {
    const ssize_t n = ::write(fd, text.data() + done, text.size() - done);
    if (n <= 0) return;
    done += size_t(n);
  }
}

// Reads `fd` until EOF (the child and everything it exec'ed have exited or closed it) or until
// the timeout, when it kills `pid`. Returns whether it timed out.
bool readUntilExit(int fd, pid_t pid, double timeoutSeconds, std::string& text) {
  const auto deadline = std::chrono::steady_clock::now() +
                        std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                            std::chrono::duration<double>(timeoutSeconds));
  char buffer[4096];
  for (;;) {
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(
                          deadline - std::chrono::steady_clock::now())
                          .count();
    if (left <= 0) {
      ::kill(pid, SIGKILL);
      return true;
    }
    pollfd p{fd, POLLIN, 0};
    const int ready = ::poll(&p, 1, int(std::min<long long>(left, 1000)));
    if (ready < 0 && errno != EINTR) return false;
    if (ready <= 0) continue;
    const ssize_t n = ::read(fd, buffer, sizeof buffer);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return false;
    text.append(buffer, size_t(n));
  }
}

std::string tail(const fs::path& file, size_t bytes) {
  std::ifstream in(file, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  std::string text = s.str();
  return text.size() > bytes ? text.substr(text.size() - bytes) : text;
}

std::string demangle(const char* name) {
  int status = 0;
  std::unique_ptr<char, void (*)(void*)> readable(
      abi::__cxa_demangle(name, nullptr, nullptr, &status), std::free);
  return status == 0 && readable ? readable.get() : name;
}

int openForOutput(const fs::path& path) {
  return ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
}

void redirect(int fd, int target) {
  if (fd >= 0) ::dup2(fd, target);
}

}  // namespace

bool sanitizerBuild() {
#if defined(__SANITIZE_ADDRESS__)
  return true;
#else
  return false;
#endif
}

std::string signalName(int signal) {
  const char* abbrev = ::sigabbrev_np(signal);
  return abbrev ? std::string("SIG") + abbrev : "signal " + std::to_string(signal);
}

std::string sanitizerSummary(const std::string& log) {
  std::istringstream in(log);
  std::string firstError;
  for (std::string line; std::getline(in, line);) {
    if (line.find("SUMMARY: ") != std::string::npos) return line;
    if (firstError.empty() && (line.find("runtime error:") != std::string::npos ||
                               line.find("ERROR: AddressSanitizer") != std::string::npos))
      firstError = line;
  }
  return firstError;
}

Outcome runInChild(const std::function<std::string()>& body, const ChildLimits& limits,
                   const fs::path& logFile) {
  int fds[2];
  if (::pipe(fds) != 0) throw Error("fuzz: cannot create a pipe");
  const pid_t pid = ::fork();
  if (pid < 0) throw Error("fuzz: cannot fork");
  if (pid == 0) {
    ::close(fds[0]);
    applyLimits(limits);
    ::setenv("LIBC_FATAL_STDERR_", "1", 1);  // glibc's heap-corruption aborts: into the log
    const int log = openForOutput(logFile);
    redirect(log, STDOUT_FILENO);
    redirect(log, STDERR_FILENO);
    std::string message;
    try {
      const std::string broken = body();
      message = (broken.empty() ? kHandled : kBrokenPromise) + broken;
    } catch (const Error& e) {
      message = kChorusError + std::string(e.what());
    } catch (const std::exception& e) {
      message = kOtherException + demangle(typeid(e).name()) + ": " + e.what();
    } catch (...) {
      message = kOtherException + std::string("an exception of unknown type");
    }
    writeAll(fds[1], message);
    ::_exit(0);
  }
  ::close(fds[1]);
  std::string message;
  const bool timedOut = readUntilExit(fds[0], pid, limits.timeoutSeconds, message);
  ::close(fds[0]);
  int status = 0;
  ::waitpid(pid, &status, 0);

  Outcome outcome;
  if (!message.empty() && !timedOut) {
    const std::string text = message.substr(1);
    switch (message[0]) {
      case kHandled:
        return outcome;
      case kChorusError:
        outcome.verdict = Verdict::Rejected;
        outcome.summary = text;
        return outcome;
      case kBrokenPromise:
        outcome.summary = text;
        break;
      default:
        outcome.summary = "uncaught " + text;
        break;
    }
  } else if (timedOut) {
    outcome.timedOut = true;
    outcome.summary = "hang: no result after " + std::to_string(int(limits.timeoutSeconds)) + " s";
  } else if (WIFSIGNALED(status)) {
    outcome.summary = "crash: " + signalName(WTERMSIG(status));
  } else {
    outcome.summary = "exit code " + std::to_string(WEXITSTATUS(status)) + " without a result";
  }
  outcome.verdict = Verdict::Finding;
  outcome.log = tail(logFile, 6000);
  if (const std::string s = sanitizerSummary(outcome.log); !s.empty())
    outcome.summary += " (" + s + ")";
  return outcome;
}

ProcessResult runProcess(const std::vector<std::string>& argv, const ChildLimits& limits,
                         const fs::path& captureDir, const fs::path& workDir) {
  fs::create_directories(captureDir);
  const fs::path outFile = captureDir / "stdout.txt", errFile = captureDir / "stderr.txt";
  int fds[2];
  if (::pipe(fds) != 0) throw Error("fuzz: cannot create a pipe");
  const pid_t pid = ::fork();
  if (pid < 0) throw Error("fuzz: cannot fork");
  if (pid == 0) {
    ::close(fds[0]);  // the write end stays open across exec: its EOF tells the parent we ended
    applyLimits(limits);
    if (::chdir(workDir.c_str()) != 0) ::_exit(127);
    redirect(openForOutput(outFile), STDOUT_FILENO);
    redirect(openForOutput(errFile), STDERR_FILENO);
    ::setenv("LIBC_FATAL_STDERR_", "1", 1);
    for (const auto& [name, ours] :
         {std::pair{"ASAN_OPTIONS", kAsanOptions}, std::pair{"UBSAN_OPTIONS", kUbsanOptions}}) {
      const char* user = std::getenv(name);
      const std::string value = std::string(ours) + (user ? std::string(":") + user : "");
      ::setenv(name, value.c_str(), 1);
    }
    std::vector<char*> cargv;
    std::vector<std::string> copies = argv;
    for (std::string& a : copies) cargv.push_back(a.data());
    cargv.push_back(nullptr);
    ::execv(cargv[0], cargv.data());
    ::_exit(127);
  }
  ::close(fds[1]);
  std::string ignored;
  ProcessResult result;
  result.timedOut = readUntilExit(fds[0], pid, limits.timeoutSeconds, ignored);
  ::close(fds[0]);
  int status = 0;
  ::waitpid(pid, &status, 0);
  if (WIFSIGNALED(status) && !result.timedOut) result.signal = WTERMSIG(status);
  if (WIFEXITED(status)) result.exitCode = WEXITSTATUS(status);
  result.out = tail(outFile, 64 * 1024);
  result.err = tail(errFile, 64 * 1024);
  return result;
}

}  // namespace chorus::fuzz
