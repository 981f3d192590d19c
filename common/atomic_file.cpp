#include "common/atomic_file.h"

#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <fstream>
#include <sstream>
#include <string_view>
#include <vector>

#include "common/error.h"
#include "common/regular_file.h"

namespace chorus {
namespace fs = std::filesystem;

namespace {
constexpr std::string_view kTemporaryTag = ".tmp";

fs::path temporaryPathFor(const fs::path& target) {
  // Unique per process and call, and in the same directory so that rename() is atomic.
  static std::atomic<unsigned> counter{0};
  fs::path tmp = target;
  tmp += std::string(kTemporaryTag) + std::to_string(::getpid()) + "_" + std::to_string(counter++);
  return tmp;
}

bool allDigits(std::string_view text) {
  return !text.empty() &&
         std::all_of(text.begin(), text.end(), [](char c) { return c >= '0' && c <= '9'; });
}
}  // namespace

bool isTemporaryFileName(const std::string& name) {
  const size_t tag = name.rfind(kTemporaryTag);
  if (tag == std::string::npos || tag == 0) return false;
  const std::string_view suffix = std::string_view(name).substr(tag + kTemporaryTag.size());
  const size_t underscore = suffix.find('_');
  return underscore != std::string_view::npos && allDigits(suffix.substr(0, underscore)) &&
         allDigits(suffix.substr(underscore + 1));
}

int removeTemporaryFiles(const fs::path& dir, bool recursive) {
  std::vector<fs::path> stale;
  std::error_code ec;
  const auto collect = [&](const fs::directory_entry& entry) {
    if (entry.is_regular_file(ec) && isTemporaryFileName(entry.path().filename().string()))
      stale.push_back(entry.path());
  };
  if (recursive) {
    for (fs::recursive_directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec))
      collect(*it);
  } else {
    for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) collect(*it);
  }
  int removed = 0;
  for (const fs::path& file : stale) removed += fs::remove(file, ec) ? 1 : 0;
  return removed;
}

std::string readFileBytes(const fs::path& file) {
  requireRegularFile(file);
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
