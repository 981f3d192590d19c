// Every registered base denoiser on buffers rendered by the chorus renderer (issue 6): the
// default scene (scenes/cornell-box.gltf), 96×96, 8 spp in K = 4 sub-buffers, against a
// 1024-spp reference. Each denoiser must beat the noisy input on the full buffer and on half A
// (whose halves are quarters 0/1), and never write NaN/Inf; the ensemble of all of them must
// beat all but the best and stay close to that one (below).
#include <gtest/gtest.h>

#include <algorithm>
#include <iostream>
#include <limits>

#include "denoise/base/registry.h"
#include "denoise/metrics/metrics.h"
#include "denoise/pipeline/ensemble.h"
#include "renderer/render.h"
#include "renderer/scene/gltf_loader.h"
#include "tests/support/denoiser_checks.h"
#include "tests/support/test_support.h"

namespace chorus {
namespace {

struct RenderedCase {
  SampleBuffers buffers;
  Image reference;
};

const RenderedCase& cornellBox() {
  static const RenderedCase rendered = [] {
    const render::Scene scene = render::buildScene(
        render::loadGltf(test::sourceDir() / "scenes/cornell-box.gltf"), render::EnvironmentDesc{});
    render::RenderOptions options;
    options.width = options.height = 96;
    options.spp = 1024;
    options.seed = 1000;  // independent of the input's samples
    RenderedCase c;
    c.reference = render::render(scene, options).buffers.part(BufferPart::Full).color.mean;
    options.spp = 8;
    options.splits = 4;
    options.seed = 1;
    c.buffers = render::render(scene, options).buffers;
    return c;
  }();
  return rendered;
}

TEST(BaseDenoisersRendered, EveryDenoiserBeatsTheNoisyInput) {
  const RenderedCase& c = cornellBox();
  ASSERT_FALSE(builtinDenoisers().empty());
  for (BufferPart part : {BufferPart::Full, BufferPart::HalfA}) {
    const DenoiseInput input = c.buffers.input(part);
    const double noisy = relMse(input.whole.color.mean, c.reference);
    for (const DenoiserEntry& entry : builtinDenoisers()) {
      ParamMap defaults;
      const auto denoiser = entry.create(defaults);
      const Image out = denoiser->run(input);
      ASSERT_EQ(test::firstNonFinite(out), "") << entry.name << " on " << partName(part);
      const double denoised = relMse(out, c.reference);
      std::cout << partName(part) << " " << entry.name << ": relMSE " << denoised << " (noisy "
                << noisy << ")\n";
      EXPECT_LT(denoised, noisy) << entry.name << " on " << partName(part);
    }
  }
}

// At 8 spp the ensemble of all seven lies within a percent of RDFC alone (0.00622 against
// 0.00622 before SBF's SURE smoothing followed the sample count, 0.00626 against 0.00622 after,
// while that change made the corpus's ensembles with SBF 0.5-0.7 % better): it must beat every
// other member and stay within 5 % of the best (issue 25 asks for 1.1x at most).
TEST(BaseDenoisersRendered, EnsembleOfAllTracksTheBestMemberAndBeatsTheRest) {
  const RenderedCase& c = cornellBox();
  std::vector<std::string> names;
  for (const DenoiserEntry& entry : builtinDenoisers()) names.push_back(entry.name);
  const EnsembleResult result = Ensemble(membersFromSpecs(names), {}).run(c.buffers);
  ASSERT_EQ(test::firstNonFinite(result.combined.image), "");
  const double ensemble = relMse(result.combined.image, c.reference);
  std::cout << "ensemble of all: relMSE " << ensemble << "\n";
  double best = std::numeric_limits<double>::infinity();
  for (const BaseOutputs& base : result.bases)
    best = std::min(best, relMse(base.full, c.reference));
  EXPECT_LT(ensemble, 1.05 * best);
  for (const BaseOutputs& base : result.bases) {
    const double member = relMse(base.full, c.reference);
    if (member > best) {
      EXPECT_LT(ensemble, member) << base.name;
    }
  }
}

}  // namespace
}  // namespace chorus
