#pragma once
// The peak memory of a render and of its denoising, estimated from the image size before the
// film or any denoiser allocates, and checked against what the machine has (memory_budget.h):
// `--width 65536 --height 65536` fails at once with one line instead of std::bad_alloc or the
// OOM killer. Bytes per pixel measured with /usr/bin/time (docs/hardening-cli.md).
#include <cstdint>
#include <span>
#include <string>

#include "denoise/pipeline/ensemble.h"
#include "renderer/render.h"

namespace chorus::cli {

// Peak bytes of rendering `size` into `splits` sub-buffers, writing render.exr and running
// `members` (none: no denoising) with their combination.
uint64_t estimatePeakBytes(render::Resolution size, int splits,
                           std::span<const EnsembleMember> members);

// Throws chorus::Error "rendering WxH with K sub-buffers and N denoisers needs X GiB, this machine
// has Y GiB available" when the estimate exceeds the memory available.
void checkRunMemory(render::Resolution size, int splits, std::span<const EnsembleMember> members);

}  // namespace chorus::cli
