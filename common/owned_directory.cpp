#include "common/owned_directory.h"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <sstream>

#include "common/atomic_file.h"
#include "common/error.h"

namespace chorus {

namespace fs = std::filesystem;

namespace {

constexpr const char* kLockFile = ".chorus.lock";
constexpr const char* kFileList = ".chorus-files";
constexpr const char* kStatsFile = "stats.json";
// Each retry means another run removed its lock file (or its empty directory) between our
// open() and flock(): it finished, so the next attempt normally succeeds.
constexpr int kLockAttempts = 100;

// The pid a lock holder wrote into the lock file ("" while it has not yet).
std::string holderPid(int fd) {
  char text[32] = {};
  const ssize_t n = ::pread(fd, text, sizeof text - 1, 0);
  std::string pid;
  for (ssize_t i = 0; i < n && text[i] >= '0' && text[i] <= '9'; ++i) pid += text[i];
  return pid;
}

// A name in DIR itself: the list is read from a file, and nothing outside DIR is ever removed.
bool isPlainFileName(const std::string& name) {
  return !name.empty() && name != "." && name != ".." && name.find('/') == std::string::npos &&
         name != kLockFile && name != kFileList;
}

std::vector<std::string> readFileList(const fs::path& file) {
  std::vector<std::string> names;
  if (!fs::exists(file)) return names;
  std::istringstream in(readFileBytes(file));
  for (std::string line; std::getline(in, line);)
    if (isPlainFileName(line)) names.push_back(line);
  return names;
}

}  // namespace

OwnedDirectory::OwnedDirectory(fs::path dir, const std::vector<std::string>& cleanSubdirectories)
    : dir_(std::move(dir)) {
  if (dir_.empty()) throw Error("the output directory is an empty path");
  const fs::path lockPath = dir_ / kLockFile;
  for (int attempt = 0; attempt < kLockAttempts && fd_ < 0; ++attempt) {
    std::error_code ec;
    if (fs::exists(dir_, ec) && !fs::is_directory(dir_, ec))
      throw fileError(dir_, "cannot create directory: it is a file");
    createdDir_ = fs::create_directories(dir_, ec) || createdDir_;
    if (ec) throw fileError(dir_, "cannot create directory: " + ec.message());
    const int fd = ::open(lockPath.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
    if (fd < 0) {
      if (errno == ENOENT) continue;  // a failed run removed the directory it had created
      throw fileError(dir_, std::string("cannot create its lock file: ") + std::strerror(errno));
    }
    if (::flock(fd, LOCK_EX | LOCK_NB) != 0) {
      const int error = errno;
      const std::string pid = holderPid(fd);
      ::close(fd);
      if (error == EWOULDBLOCK)
        throw fileError(dir_, "is in use by another chorus run" +
                                  (pid.empty() ? std::string() : " (pid " + pid + ")"));
      throw fileError(dir_, std::string("cannot lock: ") + std::strerror(error));
    }
    // The previous holder may have removed the file between our open() and flock(): locking
    // that inode owns nothing, so check that the path still names it.
    struct stat opened {
    }, named{};
    if (::fstat(fd, &opened) != 0 || ::stat(lockPath.c_str(), &named) != 0 ||
        opened.st_ino != named.st_ino || opened.st_dev != named.st_dev) {
      ::close(fd);
      continue;
    }
    const std::string pid = std::to_string(::getpid()) + "\n";
    if (::ftruncate(fd, 0) != 0 || ::pwrite(fd, pid.data(), pid.size(), 0) != ssize_t(pid.size())) {
      ::close(fd);
      throw fileError(lockPath, "cannot write");
    }
    fd_ = fd;
  }
  if (fd_ < 0) throw fileError(dir_, "cannot lock: other runs keep taking it");
  removeTemporaryFiles(dir_, false);
  for (const std::string& sub : cleanSubdirectories)
    if (fs::is_directory(dir_ / sub)) removeTemporaryFiles(dir_ / sub, true);
}

OwnedDirectory::~OwnedDirectory() {
  std::error_code ec;
  // Removed while still locked; a run that opened it meanwhile sees the inode change and retries.
  fs::remove(dir_ / kLockFile, ec);
  ::close(fd_);
  if (createdDir_) fs::remove(dir_, ec);  // only succeeds when empty
}

void OwnedDirectory::replacePreviousRun(const std::vector<std::string>& files) {
  const fs::path list = dir_ / kFileList;
  std::vector<std::string> names = readFileList(list);
  for (const std::string& file : files) {
    if (!isPlainFileName(file))
      throw Error("'" + file + "' is not a file name for " + dir_.string());
    if (std::find(names.begin(), names.end(), file) == names.end()) names.push_back(file);
  }
  std::string text;
  for (const std::string& name : names) text += name + "\n";
  writeTextAtomically(list, text);
  // stats.json first: from here on no file in DIR is described by a stats.json of another run.
  std::error_code ec;
  fs::remove(dir_ / kStatsFile, ec);
  for (const std::string& name : names) {
    if (!fs::remove(dir_ / name, ec) && ec)
      throw fileError(dir_ / name, "cannot remove the previous run's file: " + ec.message());
  }
  text.clear();
  for (const std::string& file : files) text += file + "\n";
  writeTextAtomically(list, text);
}

}  // namespace chorus
