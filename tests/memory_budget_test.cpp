// The memory check before large allocations (common/memory_budget.h).
#include <gtest/gtest.h>

#include <unistd.h>

#include "common/error.h"
#include "common/memory_budget.h"

namespace chorus {
namespace {

TEST(MemoryBudget, AvailableMemoryIsPositiveAndAtMostThePhysicalMemory) {
  const uint64_t physical = uint64_t(::sysconf(_SC_PHYS_PAGES)) * uint64_t(::sysconf(_SC_PAGESIZE));
  const uint64_t available = availableMemoryBytes();
  EXPECT_GT(available, 0u);
  EXPECT_LE(available, physical);
}

TEST(MemoryBudget, RefusesMoreThanAvailableWithOneLineSayingHowMuch) {
  const uint64_t gib = 1ull << 30;
  EXPECT_NO_THROW(checkMemoryBudget(2 * gib, "x", 2 * gib));
  try {
    checkMemoryBudget(5 * gib + gib / 2, "rendering 9x9", 2 * gib);
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_STREQ(e.what(), "rendering 9x9 needs 5.5 GiB, this machine has 2.0 GiB available");
  }
}

}  // namespace
}  // namespace chorus
