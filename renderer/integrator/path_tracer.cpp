#include "renderer/integrator/path_tracer.h"

#include <cmath>
#include <optional>

#include "renderer/integrator/bsdf.h"
#include "renderer/integrator/ray_offset.h"

namespace chorus::render {
namespace {

// Features of one path, fixed at the first non-specular vertex (see path_tracer.h).
struct FeatureRecorder {
  bool locked = false, tentative = false;
  Rgb albedo;
  Vec3f normal;
  float depth = 0;

  void record(Rgb a, Vec3f n, float d) {
    albedo = a;
    normal = n;
    depth = d;
    tentative = true;
  }
};

}  // namespace

Ray startPixelSample(Sampler& sampler, const Camera& camera, int x, int y, int sample, int splits) {
  return startCameraSample(sampler, camera, x, y, uint32_t(sample / splits), sample % splits);
}

Ray startCameraSample(Sampler& sampler, const Camera& camera, int x, int y, uint32_t index,
                      int stream) {
  sampler.startPixelSample(x, y, index, stream);
  const Vec2f offset = sampler.getPixel2D();
  // The lens sample follows the film position; pinhole renders draw none, so their dimensions
  // (and images) are what they were before cameras had lenses.
  const Vec2f lens = camera.thinLens() ? sampler.get2D() : Vec2f{};
  return camera.generateRay({float(x) + offset.x, float(y) + offset.y}, lens);
}

Rgb volumeTransmittance(const MaterialDesc& m, float distance) {
  if (!std::isfinite(m.attenuationDistance)) return Rgb(1.0f);
  Rgb t;
  for (int c = 0; c < 3; ++c) {
    const float color = std::max(m.attenuationColor[c], 1e-30f);
    t[c] = std::exp(std::log(color) * distance / m.attenuationDistance);
  }
  return t;
}

bool PathTracer::unoccluded(const SurfaceInteraction& si, const Vec3f& ng,
                            const LightSample& light) const {
  const Vec3f origin = offsetRayOrigin(si.position, si.positionError, ng, light.wi);
  if (light.isInfinite)
    return !scene_.occluded(origin, light.wi, std::numeric_limits<float>::infinity());
  Vec3f target = light.pLight;
  if (lengthSquared(light.nLight) > 0)
    target = offsetRayOrigin(light.pLight, light.pLightError, light.nLight, -light.wi);
  return !scene_.occluded(origin, target - origin, 1.0f - kShadowEpsilon);
}

PathSample PathTracer::trace(const Ray& cameraRay, Sampler& sampler, RayCounts& rays) const {
  return trace(cameraRay, sampler, rays, false);
}

Rgb PathTracer::traceEmission(const Ray& cameraRay, Sampler& sampler, RayCounts& rays) const {
  return trace(cameraRay, sampler, rays, true).emitted;
}

PathSample PathTracer::trace(const Ray& cameraRay, Sampler& sampler, RayCounts& rays,
                             bool emissionOnly) const {
  PathSample out;
  FeatureRecorder features;
  float visibility = 0;
  Rgb L(0.0f), beta(1.0f), emitted(0.0f);
  // Whether emission reached now is `emitted`: until the first vertex that is not purely
  // specular, or one of glass (it reflects or transmits at random, so what it shows varies
  // from sample to sample and is left to the denoisers).
  bool emittedOpen = true;
  float etaScale = 1.0f;  // radiance scaling by refraction, removed for roulette decisions
  Ray ray = cameraRay;
  bool previousDelta = true;  // the camera ray counts as a delta event: no MIS on its hit
  float previousPdf = 0;
  Vec3f previousPosition = cameraRay.origin;
  float pathLength = 0;
  int volumeMaterial = -1;           // the material whose interior the path is in, or −1
  std::optional<Bsdf> texturedBsdf;  // the current vertex's BSDF when a texture varies it

  for (int depth = 0;; ++depth) {
    // Sampler dimensions per bounce, in the documented order (sampler.h), drawn together once
    // the path has a vertex to scatter from.
    const uint32_t bounceDimensions = sampler.reserve(Sampler::kBounceDimensions);

    Hit hit;
    ++rays.closestHit;
    if (!scene_.intersect(ray, &hit, depth == 0)) {
      const Vec3f direction = normalize(ray.direction);
      const EnvironmentLight::Arrival arrival =
          lights_.environmentArrival(direction, !previousDelta);
      if (!arrival.Le.isBlack()) {
        const float w = previousDelta ? 1.0f : powerHeuristic(previousPdf, arrival.pdfSolidAngle);
        const Rgb contribution = beta * arrival.Le * w;
        L += contribution;
        if (emittedOpen) emitted += contribution;
      }
      if (!features.locked) {
        features.record(beta, Vec3f{}, 0.0f);
        features.locked = true;
        visibility = 1.0f;
      }
      break;
    }

    const SurfaceInteraction si = scene_.interaction(hit, ray.direction);
    const float segment = hit.t * length(ray.direction);
    pathLength += segment;
    const Material& material = scene_.material(si.material);
    if (volumeMaterial >= 0)
      beta *= volumeTransmittance(scene_.material(volumeMaterial).desc, segment);

    // Emission found by the previous BSDF sample (or seen directly).
    const Rgb Le = scene_.emitted(si);
    if (!Le.isBlack()) {
      const float w = previousDelta
                          ? 1.0f
                          : powerHeuristic(previousPdf, lights_.pdfAreaLight(previousPosition, si));
      const Rgb contribution = beta * Le * w;
      L += contribution;
      if (emittedOpen) emitted += contribution;
    }

    const Bsdf& bsdf = material.uniformBsdf ? *material.uniformBsdf
                                            : texturedBsdf.emplace(scene_.materialPoint(si));
    const bool transmissive = bsdf.hasTransmission();
    const bool specular = bsdf.isPurelySpecular();
    if (transmissive || !specular) emittedOpen = false;
    const Vec3f wo = -normalize(ray.direction);
    // Opaque surfaces are shaded from the side the ray arrives on (both sides reflect);
    // transmissive ones keep their outward frame so that wo.z < 0 means "from inside".
    Vec3f ng = si.geometricNormal, ns = si.shadingNormal;
    if (!transmissive && dot(wo, ng) < 0) ng = -ng, ns = -ns;
    // si.tangent is already orthonormal to the shading normal.
    Frame frame;
    frame.x = si.tangent;
    frame.y = cross(ns, si.tangent);
    frame.z = ns;
    Vec3f woLocal = frame.toLocal(wo);
    if (!transmissive && woLocal.z < 1e-4f) {
      // A shading normal that faces away from the viewer: shade with the geometric one.
      frame = Frame::fromZX(ng, si.tangent);
      woLocal = frame.toLocal(wo);
    }

    if (!features.locked)
      features.record(beta * bsdf.albedo(), faceForward(frame.z, wo), pathLength);
    if (depth >= settings_.maxDepth || (emissionOnly && !emittedOpen)) break;
    const Sampler::BounceDraws u = sampler.getBounce(bounceDimensions);
    const Bsdf::Outgoing outgoing = bsdf.prepare(woLocal);

    // Next-event estimation.
    bool lightVisible = false;
    if (!specular && !lights_.empty()) {
      if (const auto ls = lights_.sample(si.position, u.light, u.lightPoint)) {
        const Vec3f wiLocal = frame.toLocal(ls->wi);
        const bool sameSide = (dot(ls->wi, ng) > 0) == (dot(wo, ng) > 0);
        if (transmissive || sameSide) {
          const BsdfEval eval = bsdf.evaluate(outgoing, wiLocal);
          const Rgb f = eval.f * std::abs(wiLocal.z);
          if (!f.isBlack()) {
            ++rays.shadow;
            if (unoccluded(si, ng, *ls)) {
              const float w = ls->isDelta ? 1.0f : powerHeuristic(ls->pdf, eval.pdf);
              L += beta * f * ls->Li * (w / ls->pdf);
              lightVisible = true;
            }
          }
        }
      }
    }
    if (!features.locked && !specular) {
      features.locked = true;
      visibility = lightVisible ? 1.0f : 0.0f;
    }

    // Continue the path by sampling the BSDF.
    const auto bs = bsdf.sample(outgoing, u.lobe, u.direction);
    if (!bs || !(bs->pdf > 0) || bs->f.isBlack()) break;
    const Vec3f wi = frame.fromLocal(bs->wi);
    // Reject directions whose side of the geometric surface contradicts the lobe (possible
    // with shading normals): they would leak light through the surface.
    const bool crosses = (dot(wi, ng) > 0) != (dot(wo, ng) > 0);
    if (crosses != bs->isTransmission) break;
    beta *= bs->f * (std::abs(bs->wi.z) / bs->pdf);
    previousDelta = bs->isDelta;
    previousPdf = bs->pdf;
    previousPosition = si.position;

    if (bs->isTransmission && material.desc.hasVolume) {
      const bool entering = dot(wi, si.geometricNormal) < 0;
      volumeMaterial = entering ? si.material : -1;
      const float eta2 = material.desc.ior * material.desc.ior;
      etaScale *= entering ? eta2 : 1.0f / eta2;
    }
    ray = {offsetRayOrigin(si.position, si.positionError, ng, wi), wi,
           std::numeric_limits<float>::infinity()};

    if (depth + 1 >= settings_.rouletteStartDepth) {
      const float survive = std::min(1.0f, (beta * etaScale).maxComponent());
      if (!(u.roulette < survive)) break;
      beta = beta / survive;
    }
  }

  out.L = L;
  out.emitted = emitted;
  out.albedo = features.albedo;
  out.normal = features.normal;
  out.depth = features.depth;
  out.visibility = features.locked ? visibility : 0.0f;
  return out;
}

}  // namespace chorus::render
