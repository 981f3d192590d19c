#include "tools/fuzz/fuzz_random.h"

namespace chorus::fuzz {

FuzzRandom FuzzRandom::forCase(uint64_t seed, const std::string& target, uint64_t index) {
  uint64_t h = 1469598103934665603ull;  // FNV-1a of the target name
  for (const char c : target) h = (h ^ uint8_t(c)) * 1099511628211ull;
  FuzzRandom mix(seed ^ h);
  mix.state_ ^= index * 0x9E3779B97F4A7C15ull;
  mix.next();
  return mix;
}

uint64_t FuzzRandom::next() {
  uint64_t z = (state_ += 0x9E3779B97F4A7C15ull);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

}  // namespace chorus::fuzz
