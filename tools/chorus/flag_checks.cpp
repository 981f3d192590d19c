#include "tools/chorus/flag_checks.h"

#include <charconv>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>

namespace chorus::cli {

namespace {

// Bounds as people write them: -360, 0.5, 1e+06 (%g, not std::to_string's 1000000.000000).
std::string numberText(double v) {
  char text[32];
  std::snprintf(text, sizeof text, "%g", v);
  return text;
}

// The whole of `text` as T (decimal digits with an optional '-' for integers; for doubles also
// a fraction and an exponent), or nothing.
template <typename T>
bool parseWhole(const std::string& text, T& value) {
  const char* end = text.data() + text.size();
  const auto [stop, error] = std::from_chars(text.data(), end, value);
  return error == std::errc() && stop == end;
}

std::string got(const std::string& text) {
  return ", got '" + text + "'";
}

}  // namespace

CLI::Validator integerIn(int64_t lo, int64_t hi) {
  const std::string range = "[" + std::to_string(lo) + ", " + std::to_string(hi) + "]";
  return CLI::Validator(
      [lo, hi, range](std::string& text) -> std::string {
        int64_t v = 0;
        if (!parseWhole(text, v) || v < lo || v > hi)
          return "must be an integer in " + range + got(text);
        text = std::to_string(v);
        return {};
      },
      range);
}

CLI::Validator anyUnsigned64() {
  return CLI::Validator(
      [](std::string& text) -> std::string {
        uint64_t v = 0;
        if (!parseWhole(text, v)) return "must be an integer in [0, 2^64-1]" + got(text);
        text = std::to_string(v);
        return {};
      },
      "[0, 2^64-1]");
}

CLI::Validator finiteIn(double lo, double hi) {
  const std::string range = "[" + numberText(lo) + ", " + numberText(hi) + "]";
  return CLI::Validator(
      [lo, hi, range](std::string& text) -> std::string {
        double v = 0;
        if (!parseWhole(text, v) || !std::isfinite(v) || v < lo || v > hi)
          return "must be a number in " + range + got(text);
        return {};
      },
      range);
}

CLI::Validator zeroOrFiniteIn(double lo, double hi) {
  const std::string range = "[" + numberText(lo) + ", " + numberText(hi) + "]";
  return CLI::Validator(
      [lo, hi, range](std::string& text) -> std::string {
        double v = 0;
        if (!parseWhole(text, v) || !(v == 0 || (std::isfinite(v) && v >= lo && v <= hi)))
          return "must be 0 (off) or a number in " + range + got(text);
        return {};
      },
      "0 or " + range);
}

CLI::Validator pathName() {
  return CLI::Validator(
      [](std::string& text) -> std::string {
        if (text.empty()) return "must not be empty";
        if (text.rfind("--", 0) == 0)
          return "got '" + text + "', a flag where a file or directory name was expected";
        return std::string();
      },
      "");
}

}  // namespace chorus::cli
