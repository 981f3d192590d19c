#include "tests/support/synthetic_cases.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <random>

#include "common/error.h"
#include "denoise/pipeline/ensemble.h"

namespace chorus::synthetic {
namespace {

using Vec3 = std::array<float, 3>;

void setPixel(Image& image, int x, int y, const Vec3& v) {
  for (int c = 0; c < 3; ++c) image(x, y, c) = v[size_t(c)];
}

Vec3 normalized(Vec3 v) {
  const float length = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
  return {v[0] / length, v[1] / length, v[2] / length};
}

float dot(const Vec3& a, const Vec3& b) {
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

// Deterministic pseudo-random value in [0, 1) for an integer key (cell colours, positions).
float hashUnit(uint32_t key) {
  key ^= key >> 16;
  key *= 0x7FEB352Du;
  key ^= key >> 15;
  key *= 0x846CA68Bu;
  key ^= key >> 16;
  return float(key >> 8) * (1.0f / 16777216.0f);
}

Scene regionsScene(int w, int h) {
  Scene s{Image(w, h, 3), Image(w, h, 3), Image(w, h, 3)};
  constexpr int kCells = 14;
  std::array<std::array<float, 2>, kCells> sites{};
  for (int i = 0; i < kCells; ++i)
    sites[size_t(i)] = {hashUnit(uint32_t(2 * i + 1)), hashUnit(uint32_t(2 * i + 2))};
  const Vec3 light = normalized({0.4f, -0.5f, 0.75f});
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const float u = (x + 0.5f) / w, v = (y + 0.5f) / h;
      // Nearest and second-nearest Voronoi sites: the cell, and the distance to its border.
      int cell = 0, second = 0;
      float best = 1e9f, secondBest = 1e9f;
      for (int i = 0; i < kCells; ++i) {
        const float du = u - sites[size_t(i)][0], dv = v - sites[size_t(i)][1];
        const float d = du * du + dv * dv;
        if (d < best) {
          secondBest = best, second = cell;
          best = d, cell = i;
        } else if (d < secondBest) {
          secondBest = d, second = i;
        }
      }
      const float su = sites[size_t(second)][0] - sites[size_t(cell)][0];
      const float sv = sites[size_t(second)][1] - sites[size_t(cell)][1];
      const float border = (secondBest - best) / (2.0f * std::sqrt(su * su + sv * sv));
      const Vec3 albedo = {0.15f + 0.8f * hashUnit(uint32_t(100 + cell)),
                           0.15f + 0.8f * hashUnit(uint32_t(200 + cell)),
                           0.15f + 0.8f * hashUnit(uint32_t(300 + cell))};
      const Vec3 normal = normalized(
          {hashUnit(uint32_t(400 + cell)) - 0.5f, hashUnit(uint32_t(500 + cell)) - 0.5f, 1.0f});
      const float falloff = 1.6f / (1.0f + 2.0f * ((u - 0.3f) * (u - 0.3f) + v * v));
      // Lighting the features do not show: contact shadows along cell borders and a soft
      // shadow (penumbra about a tenth of the image wide).
      const float occlusion = 1.0f - 0.6f * std::exp(-border / 0.015f);
      const float penumbra = std::clamp((u + 0.5f * v - 0.75f) / 0.1f, 0.0f, 1.0f);
      const float shading = occlusion * (0.08f + (1.0f - 0.7f * penumbra) * falloff *
                                                     std::max(0.0f, dot(normal, light)));
      setPixel(s.albedo, x, y, albedo);
      setPixel(s.normal, x, y, normal);
      setPixel(s.truth, x, y, {albedo[0] * shading, albedo[1] * shading, albedo[2] * shading});
    }
  return s;
}

Scene shadowsScene(int w, int h) {
  Scene s{Image(w, h, 3), Image(w, h, 3), Image(w, h, 3)};
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const float u = (x + 0.5f) / w, v = (y + 0.5f) / h;
      const Vec3 albedo = {0.3f + 0.4f * u, 0.5f, 0.7f - 0.4f * v};
      const Vec3 normal = normalized({0.2f * (u - 0.5f), 0.2f * (v - 0.5f), 1.0f});
      float shading = 1.2f * (0.6f + 0.4f * u);
      // A hard shadow (a tilted half-plane) and a disc-shaped occluder's shadow.
      if (v > 0.55f + 0.3f * (u - 0.5f)) shading *= 0.15f;
      if ((u - 0.3f) * (u - 0.3f) + (v - 0.3f) * (v - 0.3f) < 0.02f) shading *= 0.25f;
      // Fine stripes (a blind's shadow), period 6 pixels, in one band.
      if (u > 0.6f && v < 0.5f && (x / 3) % 2 == 0) shading *= 0.4f;
      setPixel(s.albedo, x, y, albedo);
      setPixel(s.normal, x, y, normal);
      setPixel(s.truth, x, y, {albedo[0] * shading, albedo[1] * shading, albedo[2] * shading});
    }
  return s;
}

Scene hdrScene(int w, int h) {
  Scene s{Image(w, h, 3), Image(w, h, 3), Image(w, h, 3)};
  const float r = std::max(2.0f, 0.06f * std::min(w, h));
  const std::array<std::array<float, 2>, 2> emitters = {
      {{0.25f * w, 0.2f * h}, {0.7f * w, 0.3f * h}}};
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const float u = (x + 0.5f) / w, v = (y + 0.5f) / h;
      const bool floor = v > 0.65f;
      Vec3 albedo = floor ? Vec3{0.6f, 0.55f, 0.5f} : Vec3{0.5f, 0.5f, 0.5f};
      if (!floor && u < 0.15f) albedo = {0.7f, 0.2f, 0.2f};
      if (!floor && u > 0.85f) albedo = {0.2f, 0.6f, 0.25f};
      const Vec3 normal = floor ? Vec3{0.0f, -1.0f, 0.0f} : Vec3{0.0f, 0.0f, 1.0f};
      float shading = 0.12f + 0.25f * (1.0f - v);
      // A glossy highlight on the floor, invisible in the features.
      const float du = u - 0.5f, dv = v - 0.8f;
      shading += 12.0f * std::exp(-(du * du + dv * dv) / 0.002f);
      Vec3 radiance = {albedo[0] * shading, albedo[1] * shading, albedo[2] * shading};
      for (const auto& e : emitters)
        if ((x - e[0]) * (x - e[0]) + (y - e[1]) * (y - e[1]) < r * r) {
          albedo = {1.0f, 1.0f, 1.0f};
          radiance = {50.0f, 45.0f, 35.0f};
        }
      setPixel(s.albedo, x, y, albedo);
      setPixel(s.normal, x, y, normal);
      setPixel(s.truth, x, y, radiance);
    }
  return s;
}

float sampleSigma(float mu, float noise) {
  return noise * std::sqrt(std::max(mu, 0.0f) + 0.05f);
}

// ---- synthetic base denoisers ------------------------------------------------------------

using Kernel = std::function<float(const SubBuffer& in, int px, int py, int qx, int qy)>;

// out(p) = Σ_q k(p,q) colour(q) / Σ_q k(p,q) over a clipped (2r+1)² window.
Image kernelFilter(const SubBuffer& in, const Image& color, int radius, const Kernel& kernel) {
  const int w = color.width(), h = color.height();
  Image out(w, h, 3);
  tbb::parallel_for(0, h, [&](int y) {
    for (int x = 0; x < w; ++x) {
      double sum[3] = {0, 0, 0}, weight = 0;
      for (int qy = std::max(0, y - radius); qy <= std::min(h - 1, y + radius); ++qy)
        for (int qx = std::max(0, x - radius); qx <= std::min(w - 1, x + radius); ++qx) {
          const double k = kernel(in, x, y, qx, qy);
          for (int c = 0; c < 3; ++c) sum[c] += k * color(qx, qy, c);
          weight += k;
        }
      for (int c = 0; c < 3; ++c) out(x, y, c) = float(sum[c] / weight);
    }
  });
  return out;
}

float squaredDistance(const Image& image, int px, int py, int qx, int qy) {
  float d = 0;
  for (int c = 0; c < image.channels(); ++c) {
    const float t = image(px, py, c) - image(qx, qy, c);
    d += t * t;
  }
  return d;
}

class SyntheticDenoiser : public BaseDenoiser {
 public:
  SyntheticDenoiser(std::string name, bool features, int radius, Kernel kernel,
                    float clampValue = 0.0f)
      : name_(std::move(name)),
        features_(features),
        radius_(radius),
        kernel_(std::move(kernel)),
        clamp_(clampValue) {}
  std::string name() const override { return name_; }
  DenoiserRequirements requirements() const override { return {features_, false}; }
  Image run(const DenoiseInput& input) const override {
    Image color = input.whole.color.mean;
    if (clamp_ > 0)
      for (float& v : color.values()) v = std::min(v, clamp_);
    return kernelFilter(input.whole, color, radius_, kernel_);
  }

 private:
  std::string name_;
  bool features_;
  int radius_;
  Kernel kernel_;
  float clamp_;
};

Kernel gaussianKernel(float sigma) {
  const float k = 0.5f / (sigma * sigma);
  return [k](const SubBuffer&, int px, int py, int qx, int qy) {
    return std::exp(-k * float((px - qx) * (px - qx) + (py - qy) * (py - qy)));
  };
}

// Per channel, the median of the 5×5 window clipped to the image: a member whose error has no
// linear relation to its input's, unlike every other filter here.
class Median5Denoiser : public BaseDenoiser {
 public:
  std::string name() const override { return "median5"; }
  DenoiserRequirements requirements() const override { return {}; }
  Image run(const DenoiseInput& input) const override {
    const Image& color = input.whole.color.mean;
    const int w = color.width(), h = color.height();
    Image out(w, h, 3);
    tbb::parallel_for(0, h, [&](int y) {
      std::array<float, 25> window{};
      for (int x = 0; x < w; ++x)
        for (int c = 0; c < 3; ++c) {
          size_t n = 0;
          for (int qy = std::max(0, y - 2); qy <= std::min(h - 1, y + 2); ++qy)
            for (int qx = std::max(0, x - 2); qx <= std::min(w - 1, x + 2); ++qx)
              window[n++] = color(qx, qy, c);
          std::nth_element(window.begin(), window.begin() + long(n / 2), window.begin() + long(n));
          out(x, y, c) = window[n / 2];
        }
    });
    return out;
  }
};

class ConstantDenoiser : public BaseDenoiser {
 public:
  ConstantDenoiser(std::string name, Image image)
      : name_(std::move(name)), image_(std::move(image)) {}
  std::string name() const override { return name_; }
  DenoiserRequirements requirements() const override { return {}; }
  Image run(const DenoiseInput&) const override { return image_; }

 private:
  std::string name_;
  Image image_;
};

}  // namespace

std::string_view sceneName(SceneKind kind) {
  switch (kind) {
    case SceneKind::Regions:
      return "regions";
    case SceneKind::Shadows:
      return "shadows";
    case SceneKind::Hdr:
      return "hdr";
  }
  return "?";
}

Scene makeScene(SceneKind kind, int width, int height) {
  switch (kind) {
    case SceneKind::Regions:
      return regionsScene(width, height);
    case SceneKind::Shadows:
      return shadowsScene(width, height);
    case SceneKind::Hdr:
      return hdrScene(width, height);
  }
  throw Error("makeScene: bad kind");
}

Image expectedValue(const Scene& scene, const NoiseModel& model) {
  Image out = scene.truth;
  // A firefly sample has mean μ + 15·noise·(1 + μ).
  for (float& v : out.values()) v += model.fireflyRate * 15.0f * model.noise * (1.0f + v);
  return out;
}

SampleBuffers renderBuffers(const Scene& scene, const NoiseModel& model, int splits,
                            uint64_t seed) {
  const int w = scene.truth.width(), h = scene.truth.height();
  std::vector<SubBuffer> subs;
  for (int k = 0; k < splits; ++k) {
    SubBuffer sub = SubBuffer::zeros(w, h);
    std::mt19937_64 rng(seed * 1000003ull + uint64_t(k));
    std::normal_distribution<float> gauss(0.0f, 1.0f);
    std::uniform_real_distribution<float> uniform(0.0f, 1.0f);
    const int n = model.sppPerSplit;
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        for (int c = 0; c < 3; ++c) {
          const float mu = scene.truth(x, y, c);
          double mean = 0, m2 = 0;
          for (int i = 0; i < n; ++i) {
            float sample = mu + sampleSigma(mu, model.noise) * gauss(rng);
            if (model.fireflyRate > 0 && uniform(rng) < model.fireflyRate)
              sample = mu + 30.0f * model.noise * (1.0f + mu) * uniform(rng);
            const double delta = sample - mean;
            mean += delta / (i + 1);
            m2 += delta * (sample - mean);
          }
          sub.color.mean(x, y, c) = float(mean);
          sub.color.varianceOfMean(x, y, c) = n >= 2 ? float(m2 / (double(n) * (n - 1))) : 0.0f;
          sub.albedo.mean(x, y, c) = scene.albedo(x, y, c);
          sub.normal.mean(x, y, c) = scene.normal(x, y, c);
        }
        sub.depth.mean(x, y, 0) = 1.0f;
        sub.visibility.mean(x, y, 0) = 1.0f;
        sub.sampleCount(x, y, 0) = float(n);
      }
    subs.push_back(std::move(sub));
  }
  return SampleBuffers(std::move(subs));
}

std::unique_ptr<BaseDenoiser> createSyntheticDenoiser(const std::string& name) {
  if (name == "box1")
    return std::make_unique<SyntheticDenoiser>(
        name, false, 1, [](const SubBuffer&, int, int, int, int) { return 1.0f; });
  if (name == "gauss3")
    return std::make_unique<SyntheticDenoiser>(name, false, 9, gaussianKernel(3));
  if (name == "guided") {
    const Kernel spatial = gaussianKernel(4);
    return std::make_unique<SyntheticDenoiser>(
        name, true, 8, [spatial](const SubBuffer& in, int px, int py, int qx, int qy) {
          const float a = squaredDistance(in.albedo.mean, px, py, qx, qy) / (2 * 0.05f * 0.05f);
          const float n = squaredDistance(in.normal.mean, px, py, qx, qy) / (2 * 0.1f * 0.1f);
          return spatial(in, px, py, qx, qy) * std::exp(-a - n);
        });
  }
  if (name == "nlm") {
    const Kernel spatial = gaussianKernel(3);
    return std::make_unique<SyntheticDenoiser>(
        name, false, 7, [spatial](const SubBuffer& in, int px, int py, int qx, int qy) {
          float d = 0;
          for (int c = 0; c < 3; ++c) {
            const float vp = in.color.varianceOfMean(px, py, c);
            const float vq = in.color.varianceOfMean(qx, qy, c);
            const float diff = in.color.mean(px, py, c) - in.color.mean(qx, qy, c);
            d += std::max(0.0f, diff * diff - (vp + std::min(vp, vq))) /
                 (1e-4f + 0.45f * 0.45f * (vp + vq));
          }
          return spatial(in, px, py, qx, qy) * std::exp(-std::max(0.0f, d / 3));
        });
  }
  if (name == "biased")
    return std::make_unique<SyntheticDenoiser>(name, false, 4, gaussianKernel(1.5f), 1.5f);
  if (name == "median5") return std::make_unique<Median5Denoiser>();
  throw Error("unknown synthetic denoiser '" + name + "'");
}

std::unique_ptr<BaseDenoiser> createConstantDenoiser(const std::string& name, const Image& image) {
  return std::make_unique<ConstantDenoiser>(name, image);
}

std::vector<Case> standardCases() {
  const std::vector<std::vector<std::string>> memberSets = {
      {"box1", "gauss3", "guided", "nlm", "biased"},
      {"guided", "nlm"},
      {"gauss3", "nlm", "biased"}};
  const SceneKind scenes[] = {SceneKind::Regions, SceneKind::Shadows, SceneKind::Hdr};
  const float noises[] = {0.25f, 1.0f, 3.0f};
  std::vector<Case> cases;
  uint64_t seed = 1;
  for (SceneKind scene : scenes)
    for (float noise : noises)
      for (const auto& members : memberSets) {
        Case c;
        c.scene = scene;
        c.noise.noise = noise;
        c.noise.sppPerSplit = 4;
        c.noise.fireflyRate = scene == SceneKind::Hdr ? 0.002f : 0.0f;
        c.members = members;
        c.seed = seed++;
        c.name = std::string(sceneName(scene)) + "/noise" + std::to_string(noise).substr(0, 4) +
                 "/" + std::to_string(members.size()) + "members";
        cases.push_back(std::move(c));
      }
  return cases;
}

PreparedCase prepareCase(const Case& c, int width, int height) {
  const Scene scene = makeScene(c.scene, width, height);
  const SampleBuffers buffers = renderBuffers(scene, c.noise, 4, c.seed);
  std::vector<EnsembleMember> members;
  for (const std::string& name : c.members)
    members.push_back({name, std::shared_ptr<const BaseDenoiser>(createSyntheticDenoiser(name))});
  const EnsembleSources sources = sourcesFromBuffers(buffers);
  PreparedCase prepared;
  prepared.truth = expectedValue(scene, c.noise);
  prepared.bases = runBaseDenoisers(sources, members);
  prepared.guides = guidesFromSources(sources);
  return prepared;
}

}  // namespace chorus::synthetic
