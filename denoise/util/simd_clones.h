#pragma once
// CHORUS_SIMD_CLONES before a hot loop function builds it for AVX-512F, AVX2 and the baseline
// (GCC function multiversioning through ifunc: the CPU picks at load time), so the portable
// -march=x86-64-v2 build still runs wide vectors where they exist.
// Caution: GCC's AVX-512F target includes FMA, and C++ compiles with -ffp-contract=fast, so the
// AVX-512 clone fuses a·b + c where the others round twice: its results may differ from the
// other clones' in the last bit. CHORUS_SIMD_CLONES_EXACT also turns contraction off, so that
// every clone (and every position in a vectorised loop) gives the same bits.
#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__)
#define CHORUS_SIMD_CLONES __attribute__((target_clones("avx512f", "avx2", "default")))
#define CHORUS_SIMD_CLONES_EXACT \
  __attribute__((target_clones("avx512f", "avx2", "default"), optimize("fp-contract=off")))
#else
#define CHORUS_SIMD_CLONES
#define CHORUS_SIMD_CLONES_EXACT
#endif
