// The planes each built-in member reads (denoise/pipeline/member_planes.h), checked against the
// members themselves: replacing a plane the table leaves out by other values, or removing it,
// leaves a member's output bit-identical; replacing a plane the table lists changes it. The
// ensemble on buffers holding only what its members and the combination read gives the same
// bits as on complete buffers.
#include <gtest/gtest.h>

#include <random>

#include "common/error.h"
#include "denoise/base/registry.h"
#include "denoise/pipeline/ensemble.h"
#include "denoise/pipeline/member_planes.h"
#include "tests/support/synthetic_scene.h"
#include "tests/support/test_support.h"

namespace chorus {
namespace {

constexpr Plane kPlanes[] = {Plane::Mean, Plane::Variance};

// K = 4 sub-buffers with noisy features, so that every feature plane varies over the image.
SampleBuffers sceneBuffers() {
  test::SyntheticSceneOptions o;
  o.width = 24;
  o.height = 20;
  o.featureNoise = 0.05f;
  return test::makeSyntheticScene(o).buffers;
}

Image& planeOf(SubBuffer& sub, Quantity q, Plane p) {
  return p == Plane::Mean ? sub.get(q).mean : sub.get(q).varianceOfMean;
}

// The buffers with one plane of every sub-buffer replaced by other plausible values (a mean
// scaled and shifted per value, a variance scaled: still non-negative).
SampleBuffers perturbed(const SampleBuffers& buffers, Quantity q, Plane p) {
  std::vector<SubBuffer> subs = buffers.subBuffers();
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> factor(0.5f, 2.0f), shift(-0.3f, 0.3f);
  for (SubBuffer& sub : subs)
    for (float& v : planeOf(sub, q, p).values())
      v = v * factor(rng) + (p == Plane::Mean ? shift(rng) : 0.0f);
  return SampleBuffers(std::move(subs));
}

// The buffers holding only `planes`.
SampleBuffers stripped(const SampleBuffers& buffers, BufferPlanes planes) {
  std::vector<SubBuffer> subs = buffers.subBuffers();
  for (SubBuffer& sub : subs)
    for (Quantity q : kAllQuantities)
      for (Plane p : kPlanes)
        if (!planes.has(q, p)) planeOf(sub, q, p) = Image();
  return SampleBuffers(std::move(subs));
}

TEST(MemberPlanes, EveryMemberReadsExactlyThePlanesItsEntryLists) {
  const SampleBuffers buffers = sceneBuffers();
  ASSERT_EQ(buffers.sub(0).planes(), BufferPlanes::all());
  for (const DenoiserEntry& entry : builtinDenoisers()) {
    const std::unique_ptr<BaseDenoiser> member = createDenoiser(entry.name);
    const BufferPlanes read = planesReadBy(*member);
    const Image reference = member->run(buffers.input(BufferPart::Full));
    for (Quantity q : kAllQuantities) {
      if (q == Quantity::Color) continue;  // always held
      for (Plane p : kPlanes) {
        const Image other = member->run(perturbed(buffers, q, p).input(BufferPart::Full));
        const std::string plane = entry.name + ": " + std::string(quantityName(q)) +
                                  (p == Plane::Mean ? "" : " variance");
        if (read.has(q, p))
          EXPECT_FALSE(test::sameImage(reference, other)) << plane << " is listed but not read";
        else
          EXPECT_TRUE(test::sameImage(reference, other)) << plane << " is read but not listed";
      }
    }
    // Without the planes it does not read (empty images), the same bits.
    const Image alone = member->run(stripped(buffers, read).input(BufferPart::Full));
    EXPECT_TRUE(test::sameImage(reference, alone)) << entry.name;
  }
}

TEST(MemberPlanes, TheEnsembleOnBuffersHoldingWhatItReadsGivesTheSameBits) {
  const SampleBuffers buffers = sceneBuffers();
  const std::vector<std::string> specs = {"atrous", "nlm"};
  const std::vector<EnsembleMember> members = membersFromSpecs(specs);
  const BufferPlanes needed = planesReadBy(members, true);
  // Neither reads visibility or a feature variance; the combination reads albedo and normal.
  EXPECT_EQ(needed.list(), "albedo, normal, depth");
  EXPECT_EQ(planesReadBy(members, false).list(), "albedo, normal, depth");
  EXPECT_EQ(planesReadBy(membersFromSpecs(std::vector<std::string>{"nlm"}), true).list(),
            "albedo, normal");
  EXPECT_EQ(planesReadBy(membersFromSpecs(std::vector<std::string>{"nlm"}), false),
            BufferPlanes::colorOnly());

  const Ensemble ensemble(members, {});
  const EnsembleResult all = ensemble.run(buffers);
  const EnsembleResult some = ensemble.run(stripped(buffers, needed));
  EXPECT_TRUE(test::sameImage(all.combined.image, some.combined.image));
  for (size_t m = 0; m < members.size(); ++m)
    EXPECT_TRUE(test::sameImage(all.bases[m].full, some.bases[m].full)) << specs[m];
}

TEST(MemberPlanes, MissingPlanesAreOneLineNamingTheMemberAndThePlanes) {
  const std::vector<EnsembleMember> members =
      membersFromSpecs(std::vector<std::string>{"atrous", "nfor"});
  const BufferPlanes atrousOnly = planesReadBy(*members[0].denoiser);
  try {
    checkPlanesHeld(atrousOnly, members, false);
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_STREQ(e.what(),
                 "base denoiser 'nfor' reads albedo variance, normal variance, depth variance, "
                 "visibility, visibility variance, which the input does not hold");
  }
  const std::vector<EnsembleMember> nlm = membersFromSpecs(std::vector<std::string>{"nlm"});
  EXPECT_NO_THROW(checkPlanesHeld(BufferPlanes::colorOnly(), nlm, false));
  try {
    checkPlanesHeld(BufferPlanes::colorOnly(), nlm, true);
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_STREQ(e.what(), "the combination reads albedo, normal, which the input does not hold");
  }
}

}  // namespace
}  // namespace chorus
