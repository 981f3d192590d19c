#pragma once
// glibc hands every freed block above its mmap threshold (128 KiB at first, adapting up to
// 32 MiB) back to the kernel, and trims the heap top above 128 KiB, so each image a stage
// allocates is page-faulted and zeroed by the kernel again: ~10 % of an à-trous run at 1 Mpx
// went to page faults. Programs that run many image stages call this first so that freed
// images are reused instead. Peak memory is unchanged; memory is kept until exit.
namespace chorus {

void reuseFreedMemory();

}  // namespace chorus
