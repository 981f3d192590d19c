#include "common/thread_limit.h"

#include <string>

#include "common/error.h"

namespace chorus {

void checkThreadCount(int threads) {
  if (threads < 0 || threads > kMaxThreads)
    throw Error("--threads must be 0 (all cores) … " + std::to_string(kMaxThreads) + ", got " +
                std::to_string(threads));
}

ThreadLimit::ThreadLimit(int threads) {
  checkThreadCount(threads);
  if (threads > 0) control_.emplace(tbb::global_control::max_allowed_parallelism, size_t(threads));
}

}  // namespace chorus
