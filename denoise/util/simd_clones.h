#pragma once
// CHORUS_SIMD_CLONES before a hot loop function builds it for AVX-512F, x86-64-v3 (AVX2 with
// FMA) and the baseline (GCC function multiversioning through ifunc: the CPU picks at load time),
// so the portable -march=x86-64-v2 build still runs wide vectors where they exist. The AVX2
// clone is x86-64-v3 rather than plain AVX2 for its FMA: RDFC 8 % faster on an AVX2-only CPU.
// Caution: both wide targets include FMA, and C++ compiles with -ffp-contract=fast, so those
// clones fuse a·b + c where the baseline rounds twice: their results may differ from the
// baseline's (and the AVX-512 clone's from the v3 clone's) in the last bit.
// CHORUS_SIMD_CLONES_EXACT also turns contraction off, so that every clone (and every position in a
// vectorised loop) gives the same bits.
// -DCHORUS_NO_AVX512=ON (CMake) leaves the AVX-512 clones out and makes cpuHasAvx512f false: an
// AVX-512 machine then runs what an AVX2 CPU runs.
#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__)
#ifdef CHORUS_NO_AVX512
#define CHORUS_CLONE_TARGETS "arch=x86-64-v3", "default"
#else
#define CHORUS_CLONE_TARGETS "avx512f", "arch=x86-64-v3", "default"
#endif
#define CHORUS_SIMD_CLONES __attribute__((target_clones(CHORUS_CLONE_TARGETS)))
#define CHORUS_SIMD_CLONES_EXACT \
  __attribute__((target_clones(CHORUS_CLONE_TARGETS), optimize("fp-contract=off")))
#else
#define CHORUS_SIMD_CLONES
#define CHORUS_SIMD_CLONES_EXACT
#endif

// What the CPU running this supports, for code that picks its own path (explicit kernels, or a
// blocking that has to match the clone the ifunc resolver picked). Asked once.
inline bool cpuHasAvx512f() {
#if defined(__x86_64__) && defined(__GNUC__) && !defined(CHORUS_NO_AVX512)
  static const bool has = __builtin_cpu_supports("avx512f");
  return has;
#else
  return false;
#endif
}
inline bool cpuHasAvx2() {
#if defined(__x86_64__) && defined(__GNUC__)
  static const bool has = __builtin_cpu_supports("avx2");
  return has;
#else
  return false;
#endif
}
