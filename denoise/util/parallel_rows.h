#pragma once
// parallelRows(begin, end, body): body(y) for every row y in [begin, end), in parallel (TBB),
// with the floating-point control state (x86 MXCSR: flush-to-zero, denormals-are-zero,
// rounding) of the calling thread. TBB workers keep whatever state earlier code left on them
// (Embree's BVH builders turn on flush-to-zero), so a per-pixel loop moved from the caller onto
// the workers would otherwise treat denormal values differently from row to row.
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cstddef>

#if defined(__SSE2__)
#include <xmmintrin.h>
#endif

namespace chorus {

template <typename Body>
void parallelRows(int begin, int end, const Body& body) {
#if defined(__SSE2__)
  const unsigned int callerState = _mm_getcsr();
  tbb::parallel_for(tbb::blocked_range<int>(begin, end), [&](const tbb::blocked_range<int>& rows) {
    const unsigned int saved = _mm_getcsr();
    _mm_setcsr(callerState);
    for (int y = rows.begin(); y < rows.end(); ++y) body(y);
    _mm_setcsr(saved);
  });
#else
  tbb::parallel_for(begin, end, body);
#endif
}

// body(begin, end) for consecutive ranges covering [0, count), in parallel (parallelRows on
// chunks): element-wise loops over whole images, which are serial time between the filters'
// parallel loops otherwise.
template <typename Body>
void parallelChunks(size_t count, const Body& body) {
  constexpr size_t kChunk = size_t(1) << 15;
  const size_t chunks = (count + kChunk - 1) / kChunk;
  parallelRows(0, int(chunks), [&](int chunk) {
    const size_t begin = size_t(chunk) * kChunk;
    body(begin, std::min(count, begin + kChunk));
  });
}

}  // namespace chorus
