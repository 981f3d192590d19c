#include "tools/fuzz/byte_mutations.h"

#include <algorithm>

namespace chorus::fuzz {

const std::vector<uint64_t>& interestingIntegers() {
  static const std::vector<uint64_t> values = {0,
                                               1,
                                               2,
                                               3,
                                               4,
                                               7,
                                               8,
                                               16,
                                               0x7F,
                                               0x80,
                                               0xFF,
                                               0x100,
                                               0x7FFF,
                                               0x8000,
                                               0xFFFF,
                                               0x10000,
                                               0x7FFFFFFF,
                                               0x80000000,
                                               0xFFFFFFFF,
                                               0x100000000ull,
                                               1ull << 62,
                                               1ull << 63,
                                               ~0ull,
                                               ~1ull,
                                               0x55555556ull,
                                               0x5555555555555556ull,
                                               65535 * 2,
                                               1000000,
                                               1ull << 40,
                                               0xFFFFFFFE,
                                               0x3FFFFFFF};
  return values;
}

std::string mutateBytes(std::string& data, FuzzRandom& rng) {
  const size_t n = data.size();
  const auto at = [&] { return n ? rng.below(n) : size_t(0); };
  switch (n == 0 ? 3 : rng.below(8)) {
    case 0: {
      const size_t keep = rng.chance(0.3) ? n - std::min(n, size_t(1 + rng.below(16))) : at();
      data.resize(keep);
      return "truncate to " + std::to_string(keep) + " of " + std::to_string(n);
    }
    case 1: {
      const int flips = int(1 + rng.below(8));
      for (int i = 0; i < flips; ++i) data[at()] ^= char(1u << rng.below(8));
      return "flip " + std::to_string(flips) + " bit(s)";
    }
    case 2: {
      const size_t count = 1 + rng.below(16), pos = at();
      for (size_t i = 0; i < count && pos + i < n; ++i) data[pos + i] = char(rng.below(256));
      return "set random bytes at " + std::to_string(pos);
    }
    case 3: {
      const size_t count = 1 + rng.below(64), pos = n ? rng.below(n + 1) : 0;
      std::string inserted;
      for (size_t i = 0; i < count; ++i) inserted.push_back(char(rng.below(256)));
      data.insert(pos, inserted);
      return "insert " + std::to_string(count) + " random byte(s) at " + std::to_string(pos);
    }
    case 4: {
      const size_t pos = at(), count = std::min(n - pos, size_t(1 + rng.below(256)));
      data.erase(pos, count);
      return "delete " + std::to_string(count) + " byte(s) at " + std::to_string(pos);
    }
    case 5: {
      const size_t width = size_t(1) << rng.below(4), pos = at();
      const uint64_t value = rng.pick(interestingIntegers());
      for (size_t i = 0; i < width && pos + i < n; ++i)
        data[pos + i] = char((value >> (8 * i)) & 0xFF);
      return "write " + std::to_string(value) + " as " + std::to_string(width) + " byte(s) at " +
             std::to_string(pos);
    }
    case 6: {
      const size_t from = at(), count = std::min(n - from, size_t(1 + rng.below(512)));
      const size_t to = rng.below(n + 1);
      data.insert(to, data.substr(from, count));
      return "copy " + std::to_string(count) + " byte(s) from " + std::to_string(from) + " to " +
             std::to_string(to);
    }
    default: {
      static const std::vector<std::string> tokens = {
          "-1",         "0",  "1e309",    "-1e309", "NaN", "null",    "[",  "]",
          "{",          "}",  "\"",       ",",      ":",   "\\u0000", "\\", "18446744073709551616",
          "4294967296", "\n", "\xff\xfe", "9e99999"};
      const std::string& token = rng.pick(tokens);
      const size_t pos = rng.below(n + 1);
      data.insert(pos, token);
      return "insert token '" + token + "' at " + std::to_string(pos);
    }
  }
}

}  // namespace chorus::fuzz
