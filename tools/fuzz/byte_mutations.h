#pragma once
// Format-blind edits of a file's bytes: truncation, bit flips, random bytes set, inserted or
// deleted, little-endian "interesting" integers written over 1, 2, 4 or 8 bytes, chunks
// duplicated, and short tokens that matter in text formats inserted.
#include <string>

#include "tools/fuzz/fuzz_random.h"

namespace chorus::fuzz {

// Applies one random edit to `data` and returns what it did, e.g. "truncate to 120 of 7603".
std::string mutateBytes(std::string& data, FuzzRandom& rng);

// Integers that sit at the edges of the ranges a reader checks (as 64-bit patterns).
const std::vector<uint64_t>& interestingIntegers();

}  // namespace chorus::fuzz
