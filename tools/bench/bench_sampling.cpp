// bench_sampling: nanoseconds per call of the sampler and of the glTF BSDF, single-threaded,
// for the operations the path tracer performs per bounce (construct the BSDF at a hit, evaluate
// it for next-event estimation, sample it to continue the path). Best of --repeat runs.
#include <CLI/CLI.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "renderer/integrator/bsdf.h"
#include "renderer/sampling/sampler.h"

namespace chorus::bench {
namespace {

using render::Bsdf;
using render::MaterialPoint;
using render::Rgb;
using render::Sampler;
using render::Vec2f;
using render::Vec3f;

// Runs body(i) for i < n and returns the best time per call over `repeat` runs. The returned
// values are summed into `sink` so that the work cannot be optimised away.
double nanosecondsPerCall(int n, int repeat, double& sink, const std::function<float(int)>& body) {
  double best = std::numeric_limits<double>::infinity();
  for (int r = 0; r < repeat; ++r) {
    const auto start = std::chrono::steady_clock::now();
    double sum = 0;
    for (int i = 0; i < n; ++i) sum += body(i);
    const auto end = std::chrono::steady_clock::now();
    sink += sum;
    best = std::min(best, std::chrono::duration<double, std::nano>(end - start).count() / n);
  }
  return best;
}

Vec3f direction(float u, float v) {
  const float z = 0.02f + 0.97f * u, r = std::sqrt(1 - z * z), phi = 2 * render::kPi * v;
  return {r * std::cos(phi), r * std::sin(phi), z};
}

}  // namespace
}  // namespace chorus::bench

int main(int argc, char** argv) {
  using namespace chorus::bench;
  CLI::App app{"Nanoseconds per sampler and BSDF call (single thread)"};
  int n = 2000000, repeat = 3;
  app.add_option("--calls", n, "calls per measurement");
  app.add_option("--repeat", repeat, "runs; the best is reported");
  CLI11_PARSE(app, argc, argv);

  double sink = 0;
  Sampler sampler(1);
  std::printf("%-34s %8.1f ns\n", "sampler startPixelSample+getPixel2D",
              nanosecondsPerCall(n, repeat, sink, [&](int i) {
                sampler.startPixelSample(i & 1023, i >> 10, uint32_t(i & 63), i & 3);
                return sampler.getPixel2D().x;
              }));
  std::printf("%-34s %8.1f ns\n", "sampler get1D",
              nanosecondsPerCall(n, repeat, sink, [&](int) { return sampler.get1D(); }));
  std::printf("%-34s %8.1f ns\n", "sampler get2D",
              nanosecondsPerCall(n, repeat, sink, [&](int) { return sampler.get2D().y; }));

  struct Case {
    const char* name;
    MaterialPoint material;
  };
  MaterialPoint lambert, plastic, metal, glass;
  lambert.metallic = 0, lambert.specular = 0, lambert.baseColor = Rgb(0.7f);
  plastic.metallic = 0, plastic.roughness = 0.4f, plastic.baseColor = Rgb(0.6f, 0.3f, 0.2f);
  metal.metallic = 1, metal.roughness = 0.3f, metal.baseColor = Rgb(1.0f, 0.78f, 0.34f);
  glass.metallic = 0, glass.transmission = 1, glass.thinWalled = false, glass.roughness = 0.2f;
  for (const Case& c : {Case{"lambertian (specular 0)", lambert}, Case{"plastic r0.4", plastic},
                        Case{"metal r0.3", metal}, Case{"rough glass r0.2", glass}}) {
    const Bsdf bsdf(c.material);
    MaterialPoint m = c.material;
    const double construct = nanosecondsPerCall(n, repeat, sink, [&](int i) {
      m.baseColor.g = float(i & 255) / 256.0f;
      return Bsdf(m).albedo().g;
    });
    const double evaluate = nanosecondsPerCall(n, repeat, sink, [&](int i) {
      const Vec3f wo = direction(float(i & 1023) / 1024.0f, 0.3f);
      const Vec3f wi = direction(float((i >> 10) & 1023) / 1024.0f, 0.7f);
      return bsdf.evaluate(wo, wi).pdf;
    });
    const double sample = nanosecondsPerCall(n, repeat, sink, [&](int i) {
      const Vec3f wo = direction(float(i & 1023) / 1024.0f, 0.3f);
      const auto s = bsdf.sample(wo, float((i >> 3) & 1023) / 1024.0f,
                                 {float((i >> 5) & 255) / 256.0f, float(i & 127) / 128.0f});
      return s ? s->pdf : 0.0f;
    });
    std::printf("%-24s construct %6.1f ns  evaluate %6.1f ns  sample %6.1f ns\n", c.name, construct,
                evaluate, sample);
  }
  std::printf("(checksum %g)\n", sink);
  return 0;
}
