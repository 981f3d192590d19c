// Every real glTF scene in ../shared/scenes loads and renders at a small size: finite output,
// something visible, no warnings beyond the documented unsupported extensions, and the same
// bits from both path tracers. Scenes without lights of their own (per the folder's README) are
// lit by its HDR environments.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "renderer/render.h"
#include "renderer/scene/gltf_loader.h"
#include "tests/support/test_support.h"
#include "tests/support/tracer_comparison.h"

namespace chorus::render {
namespace {

struct SharedScene {
  const char* file;
  const char* environment;  // in _environments/, or nullptr: the scene's own lights
  std::vector<std::string> expectedWarnings;
};

const std::vector<SharedScene>& sharedScenes() {
  static const std::vector<SharedScene> scenes = {
      {"CornellBox-Bevy/CornellBox.glb", nullptr, {}},
      {"EmissiveStrengthTest/EmissiveStrengthTest.gltf", nullptr, {}},
      {"LightsPunctualLamp/LightsPunctualLamp.gltf", nullptr, {}},
      {"GlassHurricaneCandleHolder/GlassHurricaneCandleHolder.gltf", "studio_small_05_1k.hdr", {}},
      {"TransmissionTest/TransmissionTest.gltf", "aristea_wreck_puresky_1k.hdr", {}},
      {"FlightHelmet-Bevy/FlightHelmet.gltf", "studio_small_05_1k.hdr", {}},
      {"DispersionTest/DispersionTest.glb",
       "aristea_wreck_puresky_1k.hdr",
       {"ignoring unsupported extension KHR_materials_dispersion"}},
  };
  return scenes;
}

// The HDR environment a scene without lights of its own is lit by (none for the others).
EnvironmentDesc environmentOf(const std::filesystem::path& shared, const SharedScene& s) {
  if (!s.environment) return {};
  return environmentFromFile(shared / "scenes" / "_environments" / s.environment);
}

class SharedScenes : public ::testing::TestWithParam<SharedScene> {};

TEST_P(SharedScenes, LoadsAndRendersFinite) {
  CHORUS_REQUIRE_SHARED(shared);
  const SharedScene& s = GetParam();
  const std::filesystem::path file = shared / "scenes" / s.file;
  ASSERT_TRUE(std::filesystem::exists(file)) << file;
  SceneDesc desc = loadGltf(file);
  EXPECT_EQ(desc.warnings, s.expectedWarnings);
  const Scene scene = buildScene(std::move(desc), environmentOf(shared, s));
  EXPECT_FALSE(scene.usesDefaultEnvironment());

  RenderOptions o;
  o.height = 40;
  o.spp = 8;
  o.splits = 2;
  const RenderResult r = render(scene, o);
  EXPECT_EQ(r.stats.nanSamplesDropped, 0u);
  double sum = 0;
  for (int k = 0; k < 2; ++k)
    for (Quantity q : kAllQuantities)
      for (const Image* image :
           {&r.buffers.sub(k).get(q).mean, &r.buffers.sub(k).get(q).varianceOfMean})
        for (float v : image->values()) ASSERT_TRUE(std::isfinite(v)) << quantityName(q);
  const SubBuffer full = r.buffers.part(BufferPart::Full);
  for (float v : full.color.mean.values()) sum += v;
  EXPECT_GT(sum, 0.0) << "black image";
  EXPECT_EQ(r.buffers.sub(1).sampleCount.at(r.stats.width / 2, 20, 0), 4.0f);
}

// The lane tracer (forced: `auto` keeps these scenes on the one-path tracer) renders the same
// bits on real content: textures, normal maps, alpha masks, glass volumes, smooth normals,
// environment maps.
TEST_P(SharedScenes, LaneTracerRendersTheSameBits) {
  CHORUS_REQUIRE_SHARED(shared);
  const SharedScene& s = GetParam();
  const Scene scene = buildScene(loadGltf(shared / "scenes" / s.file), environmentOf(shared, s));
  RenderOptions o;
  o.height = 24;
  o.spp = 4;
  o.splits = 2;
  EXPECT_GT(test::expectTracersAgree(scene, o), 0.0);
}

INSTANTIATE_TEST_SUITE_P(Shared, SharedScenes, ::testing::ValuesIn(sharedScenes()),
                         [](const ::testing::TestParamInfo<SharedScene>& info) {
                           std::string name = info.param.file;
                           name = name.substr(0, name.find('/'));
                           std::replace(name.begin(), name.end(), '-', '_');
                           return name;
                         });

}  // namespace
}  // namespace chorus::render
