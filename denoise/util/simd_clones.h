#pragma once
// CHORUS_SIMD_CLONES before a hot loop function builds it for AVX-512F, AVX2 and the baseline
// (GCC function multiversioning through ifunc: the CPU picks at load time), so the portable
// -march=x86-64-v2 build still runs wide vectors where they exist. -mavx512f and -mavx2 do not
// enable FMA, so no contraction changes a result: every clone gives the same bits.
#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__)
#define CHORUS_SIMD_CLONES __attribute__((target_clones("avx512f", "avx2", "default")))
#else
#define CHORUS_SIMD_CLONES
#endif
