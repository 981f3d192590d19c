#include "renderer/integrator/lane_tracer.h"

#include <algorithm>
#include <array>
#include <cstring>
#include <limits>

#include "renderer/integrator/ray_offset.h"
#include "renderer/math/lanes.h"
#include "renderer/sampling/sampler.h"
#include "renderer/sampling/warps.h"

namespace chorus::render {
namespace {

namespace L = lanes;
using L::Float;
using L::Mask;

// ray_offset.h's nextFloatUp / nextFloatDown and offsetRayOrigin, lane by lane.
Float nextFloatUp(Float v) {
  // Unsigned lanes: −0.0f's pattern 0x80000000 minus 1 wraps (that lane is replaced below),
  // where a signed lane overflowed, undefined behaviour that the sanitizer build aborts on.
  const L::UInt bits = L::UInt(v);
  const L::UInt stepped = bits + L::UInt((v > 0.0f) & 2) - 1u;  // + 1 above zero, − 1 below
  return L::select(v == 0.0f, L::splat(std::numeric_limits<float>::denorm_min()), Float(stepped));
}
Float nextFloatDown(Float v) {
  return -nextFloatUp(-v);
}
Float roundAway(Float po, Float offset) {
  return L::select(offset > 0.0f, nextFloatUp(po), L::select(offset < 0.0f, nextFloatDown(po), po));
}
L::Vec3 offsetRayOrigin(const L::Vec3& p, const L::Vec3& pError, const L::Vec3& n,
                        const L::Vec3& w) {
  const Float e = L::max(L::maxComponent(pError), L::splat(kMinOffset));
  const Float d = e * (L::abs(n.x) + L::abs(n.y) + L::abs(n.z));
  L::Vec3 offset = n * d;
  offset = L::select(L::dot(w, n) < 0.0f, -offset, offset);
  const L::Vec3 po = p + offset;
  return {roundAway(po.x, offset.x), roundAway(po.y, offset.y), roundAway(po.z, offset.z)};
}

L::Vec3 barycentricPositionError(const L::Vec3& p0, const L::Vec3& p1, const L::Vec3& p2, Float b0,
                                 Float b1, Float b2) {
  return (L::abs(p0 * b0) + L::abs(p1 * b1) + L::abs(p2 * b2)) *
         L::splat(roundingGamma(7) * kOffsetSafety);
}

// Bsdf's grazingSafe: directions too close to the tangent plane (or not finite) scatter nothing.
Mask grazingSafe(const L::Vec3& w) {
  return (L::abs(w.z) >= kMinBsdfCosine) & L::isFinite(w);
}
Float cosineHemispherePdf(Float cosTheta) {
  return L::select(cosTheta > 0.0f, cosTheta * kInvPi, L::splat(0.0f));
}

// powerHeuristic (lights.h) in lanes.
Float powerHeuristic(Float a, Float b) {
  const Float a2 = a * a, b2 = b * b;
  const Float sum = a2 + b2;
  const Float w = L::select(a2 == std::numeric_limits<float>::infinity(), L::splat(1.0f), a2 / sum);
  return L::select(sum > 0.0f, w, L::splat(0.0f));
}

// sampleCosineHemisphere (warps.cpp) in lanes: the concentric disk lifted to the hemisphere.
L::Vec3 sampleCosineHemisphere(Float ux, Float uy) {
  const Float ox = 2.0f * ux - 1.0f, oy = 2.0f * uy - 1.0f;
  const Mask wide = L::abs(ox) > L::abs(oy);
  const auto t = sinCosQuarterPi((kPi / 4.0f) * L::select(wide, oy / ox, ox / oy));
  const Mask centre = (ox == 0.0f) & (oy == 0.0f);
  const Float dx = L::select(centre, L::splat(0.0f), L::select(wide, ox * t.cos, oy * t.sin));
  const Float dy = L::select(centre, L::splat(0.0f), L::select(wide, ox * t.sin, oy * t.cos));
  const Float z = L::sqrt(L::max(L::splat(0.0f), 1.0f - dx * dx - dy * dy));
  return {dx, dy, z};
}

struct LaneFrame {
  L::Vec3 x, y, z;
  L::Vec3 toLocal(const L::Vec3& v) const { return {L::dot(v, x), L::dot(v, y), L::dot(v, z)}; }
  L::Vec3 fromLocal(const L::Vec3& v) const { return x * v.x + y * v.y + z * v.z; }
};

// The paths of the four lanes (PathTracer::trace's locals, a lane each).
struct Paths {
  L::Vec3 origin, direction;
  L::Vec3 radiance, beta;
  L::Vec3 emitted;   // the part of radiance seen directly or through mirrors
  Mask emittedOpen;  // whether emission reached now goes to `emitted` (PathTracer::trace)
  Float previousPdf, pathLength;
  Float etaScale;  // radiance scaling by refraction, removed for roulette decisions
  Mask previousDelta;
  L::Int volumeMaterial;  // the material whose interior the path is in, or −1
  L::Vec3 previousPosition;
  L::Int depth;
  // Features (PathTracer's FeatureRecorder): set while not locked.
  L::Vec3 albedo, normal;
  Float featureDepth, visibility;
  Mask locked;

  void start(int i, const Ray& ray) {
    origin.set(i, ray.origin);
    direction.set(i, ray.direction);
    radiance.set(i, Rgb(0.0f));
    emitted.set(i, Rgb(0.0f));
    emittedOpen[i] = -1;
    beta.set(i, Rgb(1.0f));
    previousPdf[i] = 0;
    pathLength[i] = 0;
    etaScale[i] = 1;
    volumeMaterial[i] = -1;
    previousDelta[i] = -1;  // the camera ray counts as a delta event: no MIS on its hit
    previousPosition.set(i, ray.origin);
    depth[i] = 0;
    albedo.set(i, Rgb(0.0f));
    normal.set(i, Vec3f{});
    featureDepth[i] = 0;
    visibility[i] = 0;
    locked[i] = 0;
  }

  PathSample sample(int i) const {
    PathSample s;
    s.L = radiance.rgbAt(i);
    s.emitted = emitted.rgbAt(i);
    s.albedo = albedo.rgbAt(i);
    s.normal = normal.at(i);
    s.depth = featureDepth[i];
    s.visibility = locked[i] ? visibility[i] : 0.0f;
    return s;
  }
};

// A mask as the aligned int array Embree's packet calls take (−1: lane active).
struct LaneArray {
  alignas(16) int32_t value[L::kWidth];
  explicit LaneArray(Mask m) { std::memcpy(value, &m, sizeof value); }
};

RayPacket4 packet(const L::Vec3& origin, const L::Vec3& direction, Float tMax) {
  RayPacket4 r;
  for (int i = 0; i < L::kWidth; ++i) {
    r.ox[i] = origin.x[i], r.oy[i] = origin.y[i], r.oz[i] = origin.z[i];
    r.dx[i] = direction.x[i], r.dy[i] = direction.y[i], r.dz[i] = direction.z[i];
    r.tMax[i] = tMax[i];
  }
  return r;
}

// What PathTracer::trace knows at a hit point, for the lanes in `hit`. Plain Lambertian (and
// black) surfaces are shaded in lanes; lanes in `general` have any other BSDF, which they
// evaluate and sample one by one through their Bsdf.
struct Vertex {
  Mask hit{}, general{}, transmissive{}, specular{};
  L::Vec3 position{}, positionError{};
  L::Vec3 geometricNormal{};  // as Scene::interaction gives it (for emission, MIS and volumes)
  L::Vec3 ng{};               // turned to the side the ray arrives on (opaque surfaces)
  L::Vec3 wo{}, woLocal{};
  LaneFrame frame{};
  L::Vec3 albedo{}, f{};  // Bsdf::albedo(), and the Lambertian f (0 for black) outside `general`
  std::array<const Bsdf*, L::kWidth> bsdf{};         // `general` lanes
  std::array<Bsdf::Outgoing, L::kWidth> outgoing{};  // `general` lanes that scatter
  std::array<int, L::kWidth> material{};
};

// A vertex's sampler draws (Sampler::BounceDraws), a lane each.
struct Draws {
  Float lobe{}, directionX{}, directionY{}, light{}, lightX{}, lightY{}, roulette{};
};

// LightSample in lanes.
struct LightLanes {
  Mask sampled{}, delta{}, infinite{};
  L::Vec3 wi{}, Li{}, pLight{}, pLightError{}, nLight{};
  Float pdf{};
};

}  // namespace

// The four lanes of one tile: their pixels, samplers and paths.
class LaneTileRenderer {
 public:
  LaneTileRenderer(const LaneTracer& tracer, const LaneTracer::Tile& tile,
                   const LaneTracer::Sampling& sampling, const Camera& camera, Film& film,
                   PathTracer::RayCounts& rays, uint64_t& dropped)
      : t_(tracer),
        tile_(tile),
        sampling_(sampling),
        camera_(camera),
        film_(film),
        rays_(rays),
        dropped_(dropped),
        samplers_{Sampler(sampling.seed), Sampler(sampling.seed), Sampler(sampling.seed),
                  Sampler(sampling.seed)} {}

  void run() {
    for (int i = 0; i < L::kWidth; ++i) takePixel(i);
    while (L::any(alive_)) step();
  }

 private:
  // Per lane: its pixel, the sample being traced and the pixel's accumulators.
  struct Lane {
    int x = 0, y = 0, sample = 0;
    PixelAccumulator pixel;
  };

  void startSample(int i) {
    const Lane& l = lanes_[size_t(i)];
    p_.start(i,
             startPixelSample(samplers_[size_t(i)], camera_, l.x, l.y, l.sample, sampling_.splits));
  }

  void takePixel(int i) {
    const int width = tile_.x1 - tile_.x0;
    if (nextPixel_ == width * (tile_.y1 - tile_.y0)) {
      alive_[i] = 0;
      return;
    }
    Lane& l = lanes_[size_t(i)];
    l.x = tile_.x0 + nextPixel_ % width;
    l.y = tile_.y0 + nextPixel_ / width;
    ++nextPixel_;
    l.sample = 0;
    l.pixel = PixelAccumulator(film_.separatesEmission());
    alive_[i] = -1;
    startSample(i);
  }

  // The path of lane i has ended: accumulate it, then start the next sample or pixel.
  void finishPath(int i) {
    Lane& l = lanes_[size_t(i)];
    if (!l.pixel.add(l.sample % sampling_.splits, p_.sample(i))) ++dropped_;
    if (++l.sample < sampling_.spp) return startSample(i);
    film_.store(l.x, l.y, l.pixel);
    takePixel(i);
  }

  // One vertex of every live path.
  void step() {
    std::array<uint32_t, L::kWidth> bounceDimensions{};
    for (int i = 0; i < L::kWidth; ++i)
      if (alive_[i])
        bounceDimensions[size_t(i)] = samplers_[size_t(i)].reserve(Sampler::kBounceDimensions);
    HitPacket4 hits;
    t_.scene_->intersect4(LaneArray(alive_).value, packet(p_.origin, p_.direction, kInfinity),
                          &hits);
    rays_.closestHit += uint64_t(L::count(alive_));

    Mask ended{};
    for (int i = 0; i < L::kWidth; ++i)
      if (alive_[i] && hits.geomID[i] == HitPacket4::kNoHit) escape(i), ended[i] = -1;
    const Vertex& v = vertex(hits);
    const Mask atMaxDepth = v.hit & (p_.depth >= t_.settings_.maxDepth);
    ended |= atMaxDepth;
    const Mask scatters = v.hit & ~atMaxDepth;
    const Draws& u = draws(scatters, bounceDimensions);
    prepareGeneral(scatters);
    const Mask lit = nextEvent(v, sampleLights(v, u, scatters & ~v.specular));
    const Mask lockNow = scatters & ~v.specular & ~p_.locked;
    p_.visibility =
        L::select(lockNow, L::select(lit, L::splat(1.0f), L::splat(0.0f)), p_.visibility);
    p_.locked |= lockNow;
    ended |= scatters & ~scatter(v, u, scatters);
    for (int i = 0; i < L::kWidth; ++i)
      if (ended[i]) finishPath(i);
  }

  // Lane i's ray left the scene: the environment's radiance (MIS-weighted after a BSDF sample),
  // and the documented features of an escaped ray.
  void escape(int i) {
    const bool previousDelta = p_.previousDelta[i] != 0;
    const EnvironmentLight::Arrival arrival =
        t_.lights_->environmentArrival(normalize(p_.direction.at(i)), !previousDelta);
    if (!arrival.Le.isBlack()) {
      const float w =
          previousDelta ? 1.0f : powerHeuristic(p_.previousPdf[i], arrival.pdfSolidAngle);
      const Rgb contribution = p_.beta.rgbAt(i) * arrival.Le * w;
      p_.radiance.set(i, p_.radiance.rgbAt(i) + contribution);
      if (p_.emittedOpen[i]) p_.emitted.set(i, p_.emitted.rgbAt(i) + contribution);
    }
    if (!p_.locked[i]) {
      p_.albedo.set(i, p_.beta.rgbAt(i));
      p_.normal.set(i, Vec3f{});
      p_.featureDepth[i] = 0;
      p_.locked[i] = -1;
      p_.visibility[i] = 1;
    }
  }

  // Scene::interaction for the hit lanes (flat Lambertian triangles in lanes, others one by
  // one), the volume attenuation and emission up to there, the shading frame, and the features
  // of paths not yet locked.
  const Vertex& vertex(const HitPacket4& hits) {
    const SceneData& data = t_.scene_->data();
    Vertex& v = vertex_;
    v.hit = v.general = v.transmissive = v.specular = Mask{};
    Mask full{}, doubleSided{};  // full: the lane's SurfaceInteraction comes from the scene
    std::array<SurfaceInteraction, L::kWidth>& si = interactions_;
    L::Vec3 p0{}, p1{}, p2{}, ns{}, tangent{}, emission{};
    Float u{}, w{}, distance{};
    for (int i = 0; i < L::kWidth; ++i) {
      if (!alive_[i] || hits.geomID[i] == HitPacket4::kNoHit) continue;
      v.hit[i] = -1;
      const SceneMesh& sm = data.meshes[hits.geomID[i]];
      const uint32_t primID = hits.primID[i];
      const int materialIndex = sm.mesh.material;
      const LaneTracer::Surface& s = t_.surfaces_[size_t(materialIndex)];
      v.material[size_t(i)] = materialIndex;
      distance[i] = hits.t[i];
      if (s.inLanes && !sm.flatFrames.empty() && sm.flatFrames[primID].valid) {
        const uint32_t* idx = &sm.mesh.indices[3 * size_t(primID)];
        p0.set(i, sm.mesh.positions[idx[0]]);
        p1.set(i, sm.mesh.positions[idx[1]]);
        p2.set(i, sm.mesh.positions[idx[2]]);
        const SceneMesh::FlatFrame& flat = sm.flatFrames[primID];
        v.geometricNormal.set(i, flat.geometricNormal);
        ns.set(i, flat.shadingNormal);
        tangent.set(i, flat.tangent);
        u[i] = hits.u[i], w[i] = hits.v[i];
      } else {
        full[i] = -1;
        const SurfaceInteraction& f = si[size_t(i)] = t_.scene_->interaction(
            Hit{hits.t[i], hits.geomID[i], primID, hits.u[i], hits.v[i]}, p_.direction.at(i));
        p0.set(i, f.position);
        v.positionError.set(i, f.positionError);
        v.geometricNormal.set(i, f.geometricNormal);
        ns.set(i, f.shadingNormal);
        tangent.set(i, f.tangent);
      }
      if (s.inLanes) {
        v.albedo.set(i, s.albedo);
        v.f.set(i, s.f);
        emission.set(i, s.emission);
        doubleSided[i] = s.doubleSided ? -1 : 0;
        continue;
      }
      v.general[i] = -1;
      v.f.set(i, Rgb(0.0f));  // no shadow ray unless its Bsdf evaluates to something
      const Material& material = t_.scene_->material(materialIndex);
      const Bsdf& bsdf =
          material.uniformBsdf
              ? *material.uniformBsdf
              : texturedBsdf_[size_t(i)].emplace(t_.scene_->materialPoint(si[size_t(i)]));
      v.bsdf[size_t(i)] = &bsdf;
      v.albedo.set(i, bsdf.albedo());
      v.transmissive[i] = bsdf.hasTransmission() ? -1 : 0;
      v.specular[i] = bsdf.isPurelySpecular() ? -1 : 0;
    }
    v.position = p0;
    if (L::any(v.hit & ~full)) {  // some lane on a flat Lambertian triangle
      const Float b0 = 1.0f - u - w;
      v.position = L::select(full, p0, p0 * b0 + p1 * u + p2 * w);
      v.positionError =
          L::select(full, v.positionError, barycentricPositionError(p0, p1, p2, b0, u, w));
    }
    const Float directionLength = L::length(p_.direction);
    const Float segment = distance * directionLength;
    p_.pathLength = L::select(v.hit, p_.pathLength + segment, p_.pathLength);

    // Attenuation inside a volume, and emission found by the previous BSDF sample (or seen
    // directly): both rare, so lane by lane.
    const Mask frontFace = L::dot(p_.direction, v.geometricNormal) < 0.0f;
    emission = L::select(frontFace | doubleSided, emission, L::Vec3{});
    // Lanes whose Surface has no emission of its own (general ones) ask the scene.
    const Mask inVolume = v.hit & (p_.volumeMaterial >= 0);
    for (int i = 0; i < L::kWidth && L::any(inVolume | v.general); ++i) {
      if (inVolume[i])
        p_.beta.set(
            i, p_.beta.rgbAt(i) *
                   volumeTransmittance(t_.scene_->material(p_.volumeMaterial[i]).desc, segment[i]));
      if (v.general[i]) emission.set(i, t_.scene_->emitted(si[size_t(i)]));
    }
    const Mask emitting = v.hit & ~L::isBlack(emission);
    for (int i = 0; i < L::kWidth && L::any(emitting); ++i) {
      if (!emitting[i]) continue;
      float weight = 1.0f;
      if (!p_.previousDelta[i]) {
        SurfaceInteraction lightPoint;  // what pdfAreaLight reads
        lightPoint.position = v.position.at(i);
        lightPoint.geometricNormal = v.geometricNormal.at(i);
        lightPoint.geomID = hits.geomID[i];
        lightPoint.primID = hits.primID[i];
        weight = powerHeuristic(p_.previousPdf[i],
                                t_.lights_->pdfAreaLight(p_.previousPosition.at(i), lightPoint));
      }
      const Rgb contribution = p_.beta.rgbAt(i) * emission.rgbAt(i) * weight;
      p_.radiance.set(i, p_.radiance.rgbAt(i) + contribution);
      if (p_.emittedOpen[i]) p_.emitted.set(i, p_.emitted.rgbAt(i) + contribution);
    }

    p_.emittedOpen &= ~(v.hit & (v.transmissive | ~v.specular));

    // The shading frame: opaque surfaces are shaded from the side the ray arrives on,
    // transmissive ones keep their outward frame.
    v.wo = -(p_.direction / directionLength);
    const Mask flip = ~v.transmissive & (L::dot(v.wo, v.geometricNormal) < 0.0f);
    v.ng = L::select(flip, -v.geometricNormal, v.geometricNormal);
    ns = L::select(flip, -ns, ns);
    v.frame = {tangent, L::cross(ns, tangent), ns};
    v.woLocal = v.frame.toLocal(v.wo);
    const Mask backFacing = v.hit & ~v.transmissive & (v.woLocal.z < 1e-4f);
    for (int i = 0; i < L::kWidth && L::any(backFacing); ++i) {
      if (!backFacing[i]) continue;
      // A shading normal that faces away from the viewer: shade with the geometric one.
      const Frame g = Frame::fromZX(v.ng.at(i), tangent.at(i));
      v.frame.x.set(i, g.x), v.frame.y.set(i, g.y), v.frame.z.set(i, g.z);
      v.woLocal.set(i, g.toLocal(v.wo.at(i)));
    }

    const Mask record = v.hit & ~p_.locked;
    p_.albedo = L::select(record, p_.beta * v.albedo, p_.albedo);
    p_.normal = L::select(record, L::select(L::dot(v.frame.z, v.wo) < 0.0f, -v.frame.z, v.frame.z),
                          p_.normal);
    p_.featureDepth = L::select(record, p_.pathLength, p_.featureDepth);
    return v;
  }

  // What the light sample and the BSDF sample of a general lane share (Bsdf::prepare).
  void prepareGeneral(Mask scatters) {
    const Mask general = scatters & vertex_.general;
    for (int i = 0; i < L::kWidth && L::any(general); ++i)
      if (general[i])
        vertex_.outgoing[size_t(i)] = vertex_.bsdf[size_t(i)]->prepare(vertex_.woLocal.at(i));
  }

  const Draws& draws(Mask scatters, const std::array<uint32_t, L::kWidth>& bounceDimensions) {
    Draws& u = draws_;
    for (int i = 0; i < L::kWidth; ++i) {
      if (!scatters[i]) continue;
      const Sampler::BounceDraws d = samplers_[size_t(i)].getBounce(bounceDimensions[size_t(i)]);
      u.lobe[i] = d.lobe, u.directionX[i] = d.direction.x, u.directionY[i] = d.direction.y;
      u.light[i] = d.light, u.lightX[i] = d.lightPoint.x, u.lightY[i] = d.lightPoint.y;
      u.roulette[i] = d.roulette;
    }
    return u;
  }

  // LightSet::sample for every scattering lane: uniform area lights (the common case) in lanes,
  // any other light through LightSet::sample itself.
  const LightLanes& sampleLights(const Vertex& v, const Draws& u, Mask scatters) {
    LightLanes& ls = lightSamples_;
    ls.sampled = ls.delta = ls.infinite = Mask{};
    if (t_.lights_->empty()) return ls;
    Float pmf{}, area{};
    L::Vec3 l0{}, l1{}, l2{}, lightLe{};
    Mask inLanes{}, doubleSided{};
    for (int i = 0; i < L::kWidth; ++i) {
      if (!scatters[i]) continue;
      const LightSet::Pick pick = t_.lights_->pick(u.light[i]);
      if (!(pick.pmf > 0)) continue;
      if (const LightSet::AreaLight* light = pick.uniformArea) {
        inLanes[i] = -1;
        pmf[i] = pick.pmf;
        area[i] = light->area;
        l0.set(i, light->p0), l1.set(i, light->p1), l2.set(i, light->p2);
        ls.nLight.set(i, light->normal);
        lightLe.set(i, light->Le);
        doubleSided[i] = light->doubleSided ? -1 : 0;
        continue;
      }
      const std::optional<LightSample> s =
          t_.lights_->sample(v.position.at(i), pick, {u.lightX[i], u.lightY[i]});
      if (!s) continue;
      ls.sampled[i] = -1;
      ls.delta[i] = s->isDelta ? -1 : 0;
      ls.infinite[i] = s->isInfinite ? -1 : 0;
      ls.wi.set(i, s->wi), ls.Li.set(i, s->Li), ls.pdf[i] = s->pdf;
      ls.pLight.set(i, s->pLight), ls.pLightError.set(i, s->pLightError);
      ls.nLight.set(i, s->nLight);
    }
    if (!L::any(inLanes)) return ls;

    // LightSet::sampleArea with sampleUniformTriangle.
    const Mask half = u.lightX < u.lightY;
    const Float halfX = u.lightX / 2.0f, halfY = u.lightY / 2.0f;
    const Float b0 = L::select(half, halfX, u.lightX - halfY);
    const Float b1 = L::select(half, u.lightY - halfX, halfY);
    const Float b2 = 1.0f - b0 - b1;
    const L::Vec3 pLight = l0 * b0 + l1 * b1 + l2 * b2;
    const L::Vec3 toLight = pLight - v.position;
    const Float distanceSquared = L::dot(toLight, toLight);
    const L::Vec3 wi = toLight / L::sqrt(distanceSquared);
    const L::Vec3 Li = L::select(doubleSided | (L::dot(wi, ls.nLight) < 0.0f), lightLe, L::Vec3{});
    const Float cosLight = L::abs(L::dot(ls.nLight, wi));
    const Float pdf = distanceSquared / (cosLight * area);
    const Mask sampled = inLanes & (area > 0.0f) & (distanceSquared > 0.0f) & (cosLight > 0.0f) &
                         (pdf > 0.0f) & ~L::isBlack(Li);
    ls.sampled |= sampled;
    ls.wi = L::select(inLanes, wi, ls.wi);
    ls.Li = L::select(inLanes, Li, ls.Li);
    ls.pdf = L::select(inLanes, pdf * pmf, ls.pdf);
    ls.pLight = L::select(inLanes, pLight, ls.pLight);
    ls.pLightError =
        L::select(inLanes, barycentricPositionError(l0, l1, l2, b0, b1, b2), ls.pLightError);
    return ls;
  }

  // Next-event estimation with the light samples: the BSDF (Lambertian in lanes, others one
  // by one), the shadow rays as one packet, MIS against BSDF sampling. Returns the lanes whose
  // light was unoccluded.
  Mask nextEvent(const Vertex& v, const LightLanes& ls) {
    const L::Vec3 wiLocal = v.frame.toLocal(ls.wi);
    const Mask sameSide = (L::dot(ls.wi, v.ng) > 0.0f) == (L::dot(v.wo, v.ng) > 0.0f);
    Mask evaluated = grazingSafe(v.woLocal) & grazingSafe(wiLocal) &
                     ((v.woLocal.z < 0.0f) == (wiLocal.z < 0.0f));
    L::Vec3 f = v.f;
    Float bsdfPdf = cosineHemispherePdf(L::abs(wiLocal.z));
    const Mask evaluateOneByOne = v.general & ls.sampled & (v.transmissive | sameSide);
    for (int i = 0; i < L::kWidth && L::any(evaluateOneByOne); ++i) {
      if (!evaluateOneByOne[i]) continue;
      const BsdfEval eval = v.bsdf[size_t(i)]->evaluate(v.outgoing[size_t(i)], wiLocal.at(i));
      evaluated[i] = -1;
      f.set(i, eval.f);
      bsdfPdf[i] = eval.pdf;
    }
    const L::Vec3 fCos = f * L::abs(wiLocal.z);
    const Mask shadow = ls.sampled & (v.transmissive | sameSide) & evaluated & ~L::isBlack(fCos);
    if (!L::any(shadow)) return Mask{};
    const L::Vec3 from = offsetRayOrigin(v.position, v.positionError, v.ng, ls.wi);
    const L::Vec3 to =
        L::select(L::dot(ls.nLight, ls.nLight) > 0.0f,
                  offsetRayOrigin(ls.pLight, ls.pLightError, ls.nLight, -ls.wi), ls.pLight);
    LaneArray blocked(Mask{});
    t_.scene_->occluded4(LaneArray(shadow).value,
                         packet(from, L::select(ls.infinite, ls.wi, to - from),
                                L::select(ls.infinite, kInfinity, L::splat(1.0f - kShadowEpsilon))),
                         blocked.value);
    rays_.shadow += uint64_t(L::count(shadow));
    Mask blockedLanes;
    std::memcpy(&blockedLanes, blocked.value, sizeof blockedLanes);
    const Mask lit = shadow & ~blockedLanes;
    const Float w = L::select(ls.delta, L::splat(1.0f), powerHeuristic(ls.pdf, bsdfPdf));
    p_.radiance = L::select(lit, p_.radiance + p_.beta * fCos * ls.Li * (w / ls.pdf), p_.radiance);
    return lit;
  }

  // Continues the paths by sampling the BSDF (Bsdf::sample for a plain Lambertian in lanes,
  // others one by one), then Russian roulette. Returns the lanes whose path goes on.
  Mask scatter(const Vertex& v, const Draws& u, Mask scatters) {
    L::Vec3 wi{};
    Float pdf{};
    L::Vec3 f = v.f;
    Mask continues{};
    if (L::any(scatters & ~v.general)) {  // some lane on a Lambertian surface
      wi = sampleCosineHemisphere(u.directionX, u.directionY);
      pdf = cosineHemispherePdf(wi.z);
      continues = scatters & grazingSafe(v.woLocal) & L::isFinite(u.lobe) &
                  L::isFinite(u.directionX) & L::isFinite(u.directionY) & grazingSafe(wi) &
                  (pdf > 0.0f);
      wi.z = L::select(v.woLocal.z < 0.0f, -wi.z, wi.z);
    }
    Mask delta{}, transmission{};
    const Mask sampleOneByOne = scatters & v.general;
    for (int i = 0; i < L::kWidth && L::any(sampleOneByOne); ++i) {
      if (!sampleOneByOne[i]) continue;
      const std::optional<BsdfSample> bs = v.bsdf[size_t(i)]->sample(
          v.outgoing[size_t(i)], u.lobe[i], {u.directionX[i], u.directionY[i]});
      continues[i] = bs && bs->pdf > 0 ? -1 : 0;
      if (!continues[i]) continue;
      wi.set(i, bs->wi), f.set(i, bs->f), pdf[i] = bs->pdf;
      delta[i] = bs->isDelta ? -1 : 0;
      transmission[i] = bs->isTransmission ? -1 : 0;
    }
    continues &= ~L::isBlack(f);
    const L::Vec3 wiWorld = v.frame.fromLocal(wi);
    // Directions whose side of the geometric surface contradicts the lobe would leak light.
    const Mask crosses = (L::dot(wiWorld, v.ng) > 0.0f) != (L::dot(v.wo, v.ng) > 0.0f);
    continues &= crosses == transmission;
    L::Vec3 beta = p_.beta * (f * (L::abs(wi.z) / pdf));
    // Entering or leaving a volume (KHR_materials_volume): rare, so lane by lane.
    const Mask refracts = continues & transmission;
    for (int i = 0; i < L::kWidth && L::any(refracts); ++i) {
      if (!refracts[i]) continue;
      const MaterialDesc& m = t_.scene_->material(v.material[size_t(i)]).desc;
      if (!m.hasVolume) continue;
      const bool entering = dot(wiWorld.at(i), v.geometricNormal.at(i)) < 0;
      p_.volumeMaterial[i] = entering ? v.material[size_t(i)] : -1;
      const float eta2 = m.ior * m.ior;
      p_.etaScale[i] *= entering ? eta2 : 1.0f / eta2;
    }
    const Mask roulette = continues & (p_.depth + 1 >= t_.settings_.rouletteStartDepth);
    const Float survive = L::min(L::splat(1.0f), L::maxComponent(beta * p_.etaScale));
    continues &= ~(roulette & ~(u.roulette < survive));
    p_.beta = L::select(continues, L::select(roulette, beta / survive, beta), p_.beta);
    p_.previousDelta = L::select(continues, delta, p_.previousDelta);
    p_.previousPdf = L::select(continues, pdf, p_.previousPdf);
    p_.previousPosition = L::select(continues, v.position, p_.previousPosition);
    p_.origin = L::select(continues, offsetRayOrigin(v.position, v.positionError, v.ng, wiWorld),
                          p_.origin);
    p_.direction = L::select(continues, wiWorld, p_.direction);
    p_.depth -= continues;  // + 1 where the path goes on (masks are −1)
    return continues;
  }

  static inline const Float kInfinity = L::splat(std::numeric_limits<float>::infinity());

  const LaneTracer& t_;
  const LaneTracer::Tile& tile_;
  const LaneTracer::Sampling& sampling_;
  const Camera& camera_;
  Film& film_;
  PathTracer::RayCounts& rays_;
  uint64_t& dropped_;
  std::array<Lane, L::kWidth> lanes_;
  std::array<Sampler, L::kWidth> samplers_;
  int nextPixel_ = 0;
  Paths p_{};
  Mask alive_{};
  std::array<std::optional<Bsdf>, L::kWidth> texturedBsdf_;  // where a texture varies the BSDF
  // The current step's stages, kept between steps so that they are not cleared each time (only
  // their masks are; lanes outside them hold values of earlier steps, never read).
  Vertex vertex_;
  std::array<SurfaceInteraction, L::kWidth> interactions_;
  Draws draws_;
  LightLanes lightSamples_;
};

LaneTracer::LaneTracer(const Scene& scene, const LightSet& lights, PathTracerSettings settings)
    : scene_(&scene), lights_(&lights), settings_(settings) {
  for (const Material& material : scene.data().materials) {
    const MaterialDesc& m = material.desc;
    const Bsdf* bsdf = material.uniformBsdf ? &*material.uniformBsdf : nullptr;
    Surface s;
    s.untextured = bsdf && m.emissiveTexture < 0;
    s.inLanes = s.untextured && (bsdf->isPlainLambertian() || bsdf->scattersNothing());
    if (s.inLanes) {
      const Vec3f up{0, 0, 1};
      s.albedo = bsdf->albedo();
      s.f = bsdf->isPlainLambertian() ? bsdf->evaluate(up, up).f : Rgb(0.0f);
      s.emission = m.isEmissive() ? m.emissive : Rgb(0.0f);
      s.doubleSided = m.doubleSided;
    }
    surfaces_.push_back(s);
  }
  // The share over the triangles' areas; none of them needs measuring when every material is
  // textured (most published models: render() then stays with one path at a time).
  if (std::none_of(surfaces_.begin(), surfaces_.end(),
                   [](const Surface& s) { return s.untextured; }))
    return;
  double untexturedArea = 0, area = 0;
  for (const SceneMesh& sm : scene.data().meshes) {
    double meshArea = 0;
    for (uint32_t primID = 0; primID < sm.mesh.triangleCount(); ++primID) {
      const uint32_t* idx = &sm.mesh.indices[3 * size_t(primID)];
      const Vec3f p0 = sm.mesh.positions[idx[0]];
      meshArea +=
          0.5 *
          double(length(cross(sm.mesh.positions[idx[1]] - p0, sm.mesh.positions[idx[2]] - p0)));
    }
    area += meshArea;
    if (surfaces_[size_t(sm.mesh.material)].untextured) untexturedArea += meshArea;
  }
  untexturedAreaShare_ = area > 0 ? float(untexturedArea / area) : 0.0f;
}

void LaneTracer::renderTile(const Tile& tile, const Sampling& sampling, const Camera& camera,
                            Film& film, PathTracer::RayCounts& rays, uint64_t& dropped) const {
  LaneTileRenderer(*this, tile, sampling, camera, film, rays, dropped).run();
}

}  // namespace chorus::render
