#include "common/memory_reuse.h"

#include <cstdlib>  // defines __GLIBC__ on glibc
#if defined(__GLIBC__)
#include <malloc.h>
#endif

namespace chorus {

void reuseFreedMemory() {
#if defined(__GLIBC__)
  mallopt(M_MMAP_THRESHOLD, 32 << 20);  // the largest glibc accepts (HEAP_MAX_SIZE / 2)
  mallopt(M_TRIM_THRESHOLD, 1 << 30);
#endif
}

}  // namespace chorus
