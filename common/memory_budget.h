#pragma once
// How much memory a run may still take, and one check against it before a large allocation (the
// film of a render, the denoisers' working set): a request the machine cannot hold fails with
// one line saying how much it needs, instead of std::bad_alloc or the kernel's OOM killer
// halfway through the work.
#include <cstdint>
#include <string>

namespace chorus {

// Bytes the kernel can hand this process without swapping: MemAvailable of /proc/meminfo (else
// sysconf's available physical pages), lowered to what a cgroup v2 memory limit (memory.max −
// memory.current) or RLIMIT_AS still allows.
uint64_t availableMemoryBytes();

// "12.3 GiB" (one decimal), for messages.
std::string gibText(uint64_t bytes);

// Throws chorus::Error "<what> needs N GiB, this machine has M GiB available" when `bytes`
// exceeds `available`.
void checkMemoryBudget(uint64_t bytes, const std::string& what, uint64_t available);
// The same against availableMemoryBytes().
void checkMemoryBudget(uint64_t bytes, const std::string& what);

}  // namespace chorus
