#include "denoise/pipeline/member_runner.h"

namespace chorus {

MemberRunner::MemberRunner(const DenoiseInput& input, std::span<const EnsembleMember> members)
    : input_(input), members_(members) {
  std::vector<const OutlierGuardOptions*> guards;
  for (const EnsembleMember& member : members) {
    const auto* guarded = dynamic_cast<const GuardedDenoiser*>(member.denoiser.get());
    guarded_.push_back(guarded);
    int index = -1;
    if (guarded) {
      for (size_t k = 0; k < guards.size() && index < 0; ++k)
        if (*guards[k] == guarded->guard()) index = int(k);
      if (index < 0) {
        index = int(guards.size());
        guards.push_back(&guarded->guard());
        prepared_.push_back(prepareInput(input, guarded->guard()));
      }
    }
    preparedOf_.push_back(index);
  }
}

Image MemberRunner::run(size_t m) const {
  if (guarded_[m]) return guarded_[m]->runPrepared(prepared_[size_t(preparedOf_[m])], input_);
  return members_[m].denoiser->run(input_);
}

}  // namespace chorus
