#include "tools/chorus/memory_estimate.h"

#include <algorithm>
#include <map>

#include "common/memory_budget.h"

namespace chorus::cli {

namespace {

// Calibrated against peak RSS (/usr/bin/time) of cornell-box renders at 4 spp, --threads 2;
// docs/hardening-cli.md has every run and the command.
// Process, scene, Embree and TBB: the intercept of 480x270 and 960x540 render-only runs.
constexpr double kFixedBytes = 40.0 * (1 << 20);
// Per pixel and sub-buffer while rendering and writing render.exr: the film's 23 float planes
// (92 bytes) plus the write's buffers (measured 141 at K = 1, 134 per sub-buffer at K = 4).
constexpr double kRenderBytesPerSubBuffer = 141;
// The denoisers' inputs: copies of 23 float planes. At K = 4, 9: the sources keep 7 (A and B
// with two halves each, the full buffer) and the held-out input being run holds 3, prepared
// once for all members (member_runner.h), less what is freed by then (measured 6.6-7.5; 9 keeps
// the estimate 5-8 % above every calibration point). The input of a run on the full buffer with
// its halves (3) is built one at a time with the held-out inputs. At K = 2, 5 (no halves in A
// and B).
constexpr double kSourceBytesPerCopy = 92;
constexpr int kSourceCopiesK4 = 9, kSourceCopiesK2 = 5;
// Per pixel, what a member's runs and the combination add at their peak (the member
// alone, K = 4, beyond the render and the sources). Peaks of several members did not add up
// (480x270: nfor alone 338 MiB, nfor,rdfc,atrous 347 MiB, all seven members 328 MiB): the
// largest counts in full, every further member only its outputs (kFurtherMemberBytes).
const std::map<std::string, double>& memberPeakBytes() {
  static const std::map<std::string, double> measured = {
      {"atrous", 162}, {"bilateral", 212}, {"nlm", 312},  {"sbf", 370},
      {"jnlm", 389},   {"rdfc", 800},      {"nfor", 1095}};
  return measured;
}
// A member's outputs plus its weight map: full and four held-out runs at K = 4 with the
// quarters estimate (5 × RGB float; full, A and B, 40 bytes, with the halves estimate).
constexpr double kFurtherMemberBytes = 64;

double memberPeak(const EnsembleMember& member) {
  const auto& measured = memberPeakBytes();
  const auto it = measured.find(member.denoiser->name());
  if (it != measured.end()) return it->second;
  double largest = 0;  // an unmeasured member: as much as the largest measured one
  for (const auto& [name, bytes] : measured) largest = std::max(largest, bytes);
  return largest;
}

}  // namespace

uint64_t estimatePeakBytes(render::Resolution size, int splits,
                           std::span<const EnsembleMember> members) {
  const double pixels = double(size.width) * double(size.height);
  double perPixel = splits * kRenderBytesPerSubBuffer;
  if (!members.empty()) {
    perPixel += (splits == 4 ? kSourceCopiesK4 : kSourceCopiesK2) * kSourceBytesPerCopy;
    double largest = 0;
    for (const EnsembleMember& member : members) largest = std::max(largest, memberPeak(member));
    perPixel += largest + double(members.size() - 1) * kFurtherMemberBytes;
  }
  return uint64_t(kFixedBytes + pixels * perPixel);
}

void checkRunMemory(render::Resolution size, int splits, std::span<const EnsembleMember> members) {
  std::string what = "rendering " + std::to_string(size.width) + "x" + std::to_string(size.height) +
                     " with " + std::to_string(splits) + " sub-buffer(s)";
  if (!members.empty()) what += " and " + std::to_string(members.size()) + " denoiser(s)";
  checkMemoryBudget(estimatePeakBytes(size, splits, members), what);
}

}  // namespace chorus::cli
