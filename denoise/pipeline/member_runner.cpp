#include "denoise/pipeline/member_runner.h"

namespace chorus {

MemberRunner::MemberRunner(const DenoiseInput& input, std::span<const EnsembleMember> members)
    : input_(input), members_(members) {
  for (size_t m = 0; m < members.size(); ++m) {
    const auto* guarded = dynamic_cast<const GuardedDenoiser*>(members[m].denoiser.get());
    guarded_.push_back(guarded);
    preparedOf_.push_back(-1);
    if (!guarded) continue;
    // An earlier member with the same guard has prepared the input already.
    for (size_t j = 0; j < m && preparedOf_[m] < 0; ++j)
      if (guarded_[j] && guarded_[j]->guard() == guarded->guard()) preparedOf_[m] = preparedOf_[j];
    if (preparedOf_[m] >= 0) continue;
    preparedOf_[m] = int(prepared_.size());
    prepared_.push_back(prepareInput(input, guarded->guard()));
  }
}

Image MemberRunner::run(size_t m) const {
  if (guarded_[m]) return guarded_[m]->runPrepared(prepared_[size_t(preparedOf_[m])], input_);
  return members_[m].denoiser->run(input_);
}

}  // namespace chorus
