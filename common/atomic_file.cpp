#include "common/atomic_file.h"

#include <unistd.h>

#include <atomic>
#include <fstream>
#include <sstream>

#include "common/error.h"

namespace chorus {
namespace fs = std::filesystem;

namespace {
fs::path temporaryPathFor(const fs::path& target) {
  // Unique per process and call, and in the same directory so that rename() is atomic.
  static std::atomic<unsigned> counter{0};
  fs::path tmp = target;
  tmp += ".tmp" + std::to_string(::getpid()) + "_" + std::to_string(counter++);
  return tmp;
}
}  // namespace

std::string readFileBytes(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw fileError(file, "cannot open");
  std::ostringstream bytes;
  bytes << in.rdbuf();
  return bytes.str();
}

void ensureDirectory(const fs::path& dir) {
  if (dir.empty()) return;
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec || !fs::is_directory(dir))
    throw fileError(dir, "cannot create directory: " + ec.message());
}

void writeAtomically(const fs::path& target, const std::function<void(const fs::path&)>& write) {
  const fs::path parent = target.parent_path();
  if (!parent.empty() && !fs::is_directory(parent)) throw fileError(parent, "no such directory");
  const fs::path tmp = temporaryPathFor(target);
  try {
    write(tmp);
  } catch (...) {
    std::error_code ignored;
    fs::remove(tmp, ignored);
    throw;
  }
  std::error_code ec;
  fs::rename(tmp, target, ec);
  if (ec) {
    fs::remove(tmp, ec);
    throw fileError(target, "cannot write: " + ec.message());
  }
}

void writeTextAtomically(const fs::path& target, const std::string& text) {
  writeAtomically(target, [&](const fs::path& tmp) {
    std::ofstream out(tmp, std::ios::binary);
    if (!out) throw fileError(target, "cannot open for writing");
    out << text;
    out.close();
    if (!out) throw fileError(target, "write failed (disk full?)");
  });
}

}  // namespace chorus
