#pragma once
// A sweep small enough for unit tests (well under a second): the project's Cornell box at
// 32×32, 4 and 8 spp, the two fastest base denoisers, a 256-spp reference.
#include <filesystem>

#include "tools/sweep/sweep_runner.h"

namespace chorus::test {

sweep::SweepConfig tinySweepConfig(const std::filesystem::path& out);

// Rows per case of tinySweepConfig: noisy + 2 bases + 1 combination × 5 combiners.
inline constexpr size_t kTinySweepRowsPerCase = 1 + 2 + 5;

}  // namespace chorus::test
