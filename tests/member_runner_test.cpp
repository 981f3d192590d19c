// MemberRunner prepares an input once per guard setting for all the members that share it: each
// member's output must be exactly its own run on the input, whatever the other members are.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "denoise/base/outlier_guard.h"
#include "denoise/pipeline/ensemble_sources.h"
#include "denoise/pipeline/held_out_inputs.h"
#include "denoise/pipeline/member_runner.h"
#include "tests/support/synthetic_cases.h"

namespace chorus {
namespace {

bool identical(const Image& a, const Image& b) {
  if (!a.sameShape(b)) return false;
  for (size_t i = 0; i < a.size(); ++i)
    if (a.data()[i] != b.data()[i]) return false;
  return true;
}

TEST(MemberRunner, EveryMemberGetsExactlyItsOwnRunsOutput) {
  // Bright emitters with fireflies, so that the guard clamps values and the preparations for
  // the default guard and for guard=0 differ.
  const synthetic::Scene scene = synthetic::makeScene(synthetic::SceneKind::Hdr, 40, 32);
  const SampleBuffers buffers = synthetic::renderBuffers(scene, {1.0f, 2, 0.03f}, 4, 5);
  const EnsembleSources sources = sourcesFromBuffers(buffers);
  std::vector<EnsembleMember> members =
      membersFromSpecs(std::vector<std::string>{"atrous", "nfor", "atrous:guard=0", "sbf"});
  members.push_back({"box1", synthetic::createSyntheticDenoiser("box1")});  // not guarded

  for (const DenoiseInput& input : {sources.full, heldOutInput(sources, 2)}) {
    ASSERT_GT(guardOutliers(input).clampedValues, 0u);
    const MemberRunner runner(input, members);
    std::vector<Image> shared;
    for (size_t m = 0; m < members.size(); ++m) {
      shared.push_back(runner.run(m));
      EXPECT_TRUE(identical(shared.back(), members[m].denoiser->run(input))) << members[m].label;
    }
    EXPECT_FALSE(identical(shared[0], shared[2])) << "atrous with and without the guard";
  }
}

}  // namespace
}  // namespace chorus
