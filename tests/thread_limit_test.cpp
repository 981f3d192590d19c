// ThreadLimit, the process-wide TBB limit behind every --threads flag (common/thread_limit.h):
// while one is alive, parallel work runs on at most that many threads.
#include <gtest/gtest.h>
#include <tbb/parallel_for.h>

#include <chrono>
#include <mutex>
#include <set>
#include <thread>

#include "common/error.h"
#include "common/thread_limit.h"

namespace chorus {
namespace {

// The distinct threads that ran 64 tasks of 2 ms each (long enough for TBB to wake every worker
// it may use).
size_t threadsThatRan() {
  std::mutex mutex;
  std::set<std::thread::id> ids;
  tbb::parallel_for(0, 64, [&](int) {
    const auto end = std::chrono::steady_clock::now() + std::chrono::milliseconds(2);
    while (std::chrono::steady_clock::now() < end) {
    }
    const std::lock_guard lock(mutex);
    ids.insert(std::this_thread::get_id());
  });
  return ids.size();
}

TEST(ThreadLimit, OneThreadRunsEveryTask) {
  const ThreadLimit limit(1);
  EXPECT_EQ(threadsThatRan(), 1u);
}

// Negative control: with two allowed and two cores, the same work spreads over two threads (a
// few tries, in case the machine is busy), so the test above can tell a limit from none.
TEST(ThreadLimit, TwoThreadsAreUsedWhenAllowed) {
  if (std::thread::hardware_concurrency() < 2) GTEST_SKIP() << "one core";
  const ThreadLimit limit(2);
  size_t most = 0;
  for (int attempt = 0; attempt < 5 && most < 2; ++attempt) most = threadsThatRan();
  EXPECT_EQ(most, 2u);
}

TEST(ThreadLimit, RejectsCountsOutsideItsRange) {
  EXPECT_THROW(ThreadLimit(-1), Error);
  EXPECT_THROW(ThreadLimit(kMaxThreads + 1), Error);
  EXPECT_NO_THROW(ThreadLimit(0));
}

}  // namespace
}  // namespace chorus
