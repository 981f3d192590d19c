#pragma once
// The fuzzer's random numbers: splitmix64, so that a (seed, target, case index) triple names the
// same input on every machine and standard library (std:: distributions are not portable).
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace chorus::fuzz {

class FuzzRandom {
 public:
  explicit FuzzRandom(uint64_t seed) : state_(seed) {}
  // The generator of case `index` of a run: independent of every other case, so one case can be
  // regenerated alone (--case).
  static FuzzRandom forCase(uint64_t seed, const std::string& target, uint64_t index);

  uint64_t next();
  // Uniform in [0, n); n > 0.
  size_t below(size_t n) { return size_t(next() % n); }
  // Uniform in [lo, hi].
  int64_t between(int64_t lo, int64_t hi) { return lo + int64_t(below(size_t(hi - lo) + 1)); }
  bool chance(double p) { return double(next() >> 11) * 0x1.0p-53 < p; }
  template <typename T>
  const T& pick(const std::vector<T>& items) {
    return items[below(items.size())];
  }

 private:
  uint64_t state_;
};

}  // namespace chorus::fuzz
