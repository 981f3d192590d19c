#pragma once
// One range check per flag: CLI11 validators that read the flag's text before CLI11 converts it,
// so that "1e7", "-1", "2^64" or "nan" never saturate or wrap into an int or a seed, with short
// messages ("--threads: must be an integer in 0 … 1024, got 1e7"; CLI11's own Range prints
// DBL_MAX in full). Attach them with ->transform(): integers are rewritten in plain decimal,
// which CLI11's base-0 conversion would otherwise read "010" as octal.
#include <CLI/CLI.hpp>

#include <cstdint>

namespace chorus::cli {

// A decimal integer in [lo, hi].
CLI::Validator integerIn(int64_t lo, int64_t hi);
// A decimal integer in [0, 2^64-1] (seeds: every value is a different seed).
CLI::Validator anyUnsigned64();
// A finite number in [lo, hi].
CLI::Validator finiteIn(double lo, double hi);
// 0 (off) or a finite number in [lo, hi].
CLI::Validator zeroOrFiniteIn(double lo, double hi);
// A file or directory name: not empty (an empty --out would write into the current directory)
// and not starting with "--" (`--out --image-prior=1` took the flag for a directory's name and
// wrote there, leaving the flag unread).
CLI::Validator pathName();

// The ranges shared by several commands, each with the reason for its bound.
// Image sides: 65536² pixels already need terabytes; the memory check (memory_estimate.h)
// decides what fits, this bound only keeps every pixel count far from overflow.
inline constexpr int64_t kMaxImageSide = 65536;
// Sample counts are stored per pixel as float, exact up to 2^24.
inline constexpr int64_t kMaxSpp = int64_t(1) << 24;
// No path tracer needs more bounces; each one is a loop iteration, not memory.
inline constexpr int64_t kMaxDepth = 1024;
// Radiance scales: beyond this a float radiance overflows to Inf after a few bounces.
inline constexpr double kMaxRadianceScale = 1e6;
// The ensemble's K-style factors (outlier cap, consistency, plausibility, image prior, noisy
// fallback): far beyond any useful value, and small enough that K² stays finite in float.
inline constexpr double kMaxEnsembleFactor = 1e6;
// MSE window radius: (2r+1)² taps per pixel; r = 32 is already ~4000 taps.
inline constexpr int64_t kMaxWindowRadius = 32;

}  // namespace chorus::cli
