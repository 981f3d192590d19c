#include "tests/support/tracer_comparison.h"

#include "tests/support/test_support.h"

#include <gtest/gtest.h>

#include <algorithm>

namespace chorus::test {

double expectTracersAgree(const render::Scene& scene, render::RenderOptions options) {
  options.tracer = render::RenderOptions::Tracer::OnePath;
  const render::RenderResult onePath = render::render(scene, options);
  options.tracer = render::RenderOptions::Tracer::Lanes;
  const render::RenderResult lanes = render::render(scene, options);
  EXPECT_FALSE(onePath.stats.lanes);
  EXPECT_TRUE(lanes.stats.lanes);
  for (int k = 0; k < options.splits; ++k)
    for (Quantity q : kAllQuantities) {
      const auto& a = onePath.buffers.sub(k).get(q);
      const auto& b = lanes.buffers.sub(k).get(q);
      EXPECT_TRUE(sameImage(a.mean, b.mean)) << quantityName(q) << " mean, sub-buffer " << k;
      EXPECT_TRUE(sameImage(a.varianceOfMean, b.varianceOfMean))
          << quantityName(q) << " variance, sub-buffer " << k;
    }
  EXPECT_TRUE(sameImage(onePath.buffers.emission(), lanes.buffers.emission())) << "emission";
  EXPECT_EQ(onePath.buffers.emission().empty(), !options.separateEmission);
  EXPECT_EQ(onePath.stats.emissionPixels, lanes.stats.emissionPixels);
  EXPECT_EQ(onePath.stats.rays, lanes.stats.rays);
  EXPECT_EQ(onePath.stats.shadowRays, lanes.stats.shadowRays);
  EXPECT_EQ(onePath.stats.nanSamplesDropped, lanes.stats.nanSamplesDropped);
  const auto& colour = onePath.buffers.sub(0).color.mean.values();
  double sum = 0;
  for (float v : colour) sum += double(v);
  return sum / double(colour.size());
}

}  // namespace chorus::test
