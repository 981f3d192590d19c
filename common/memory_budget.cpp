#include "common/memory_budget.h"

#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <optional>
#include <string>

#include "common/error.h"

namespace chorus {

namespace {

// The value of "Key:  N kB" in /proc/meminfo, in bytes.
std::optional<uint64_t> meminfoBytes(const std::string& key) {
  std::ifstream in("/proc/meminfo");
  std::string name;
  uint64_t kib = 0;
  std::string unit;
  while (in >> name >> kib >> unit)
    if (name == key + ":") return kib * 1024;
  return std::nullopt;
}

// A cgroup v2 file holding one number ("max" when unlimited).
std::optional<uint64_t> cgroupValue(const char* file) {
  std::ifstream in(file);
  std::string text;
  if (!(in >> text) || text == "max") return std::nullopt;
  try {
    return std::stoull(text);
  } catch (const std::exception&) {
    return std::nullopt;
  }
}

}  // namespace

uint64_t availableMemoryBytes() {
  uint64_t available = 0;
  if (const auto bytes = meminfoBytes("MemAvailable")) {
    available = *bytes;
  } else {
    const long pages = ::sysconf(_SC_AVPHYS_PAGES), pageSize = ::sysconf(_SC_PAGESIZE);
    available = pages > 0 && pageSize > 0 ? uint64_t(pages) * uint64_t(pageSize) : UINT64_MAX;
  }
  // Inside a container the cgroup's limit, not the host's free memory, is what runs out first.
  const auto limit = cgroupValue("/sys/fs/cgroup/memory.max");
  const auto used = cgroupValue("/sys/fs/cgroup/memory.current");
  if (limit) available = std::min(available, *limit - std::min(*limit, used.value_or(0)));
  rlimit addressSpace{};
  if (::getrlimit(RLIMIT_AS, &addressSpace) == 0 && addressSpace.rlim_cur != RLIM_INFINITY)
    available = std::min<uint64_t>(available, addressSpace.rlim_cur);
  return available;
}

std::string gibText(uint64_t bytes) {
  char text[32];
  std::snprintf(text, sizeof text, "%.1f GiB", double(bytes) / double(1ull << 30));
  return text;
}

void checkMemoryBudget(uint64_t bytes, const std::string& what, uint64_t available) {
  if (bytes > available)
    throw Error(what + " needs " + gibText(bytes) + ", this machine has " + gibText(available) +
                " available");
}

void checkMemoryBudget(uint64_t bytes, const std::string& what) {
  checkMemoryBudget(bytes, what, availableMemoryBytes());
}

}  // namespace chorus
