#pragma once
// Runs an ensemble's members on one input, preparing the input (non-finite colour filled,
// fireflies clamped, radiance scaled: guarded_denoiser.h) once for all the guarded members that
// share guard options, instead of once per member. The same outputs as each member's own run;
// one prepared copy of the input alive instead of one per member running at the same time, and
// one outlier guard pass instead of one per member.
#include <span>
#include <vector>

#include "denoise/base/guarded_denoiser.h"
#include "denoise/pipeline/ensemble.h"

namespace chorus {

class MemberRunner {
 public:
  // Prepares `input` (which must outlive the runner) for every distinct guard among `members`.
  MemberRunner(const DenoiseInput& input, std::span<const EnsembleMember> members);

  // Member m's output on the input; thread-safe (members may run at once).
  Image run(size_t m) const;

 private:
  const DenoiseInput& input_;
  std::span<const EnsembleMember> members_;
  std::vector<const GuardedDenoiser*> guarded_;  // per member; null: not a guarded member
  std::vector<int> preparedOf_;                  // per member: its entry of prepared_, or −1
  std::vector<PreparedInput> prepared_;
};

}  // namespace chorus
