#pragma once
// parallelRows(begin, end, body): body(y) for every row y in [begin, end), in parallel (TBB),
// with the floating-point control state (x86 MXCSR: flush-to-zero, denormals-are-zero,
// rounding) of the calling thread. TBB workers keep whatever state earlier code left on them
// (Embree's BVH builders turn on flush-to-zero), so a per-pixel loop moved from the caller onto
// the workers would otherwise treat denormal values differently from row to row.
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

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

}  // namespace chorus
