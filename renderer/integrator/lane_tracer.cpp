#include "renderer/integrator/lane_tracer.h"

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
  const L::Int bits = L::Int(v);
  const L::Int stepped = v > 0.0f ? bits + 1 : bits - 1;
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
  Float previousPdf, pathLength;
  Mask previousDelta;
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
    beta.set(i, Rgb(1.0f));
    previousPdf[i] = 0;
    pathLength[i] = 0;
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
    s.albedo = albedo.rgbAt(i);
    s.normal = normal.at(i);
    s.depth = featureDepth[i];
    s.visibility = locked[i] ? visibility[i] : 0.0f;
    return s;
  }
};

int countLanes(Mask m) {
  return __builtin_popcount(unsigned(_mm_movemask_ps(__m128(m))));
}

// A mask as the aligned int array Embree's packet calls take (−1: lane active).
struct LaneArray {
  alignas(16) int32_t value[L::kWidth];
  explicit LaneArray(Mask m) { std::memcpy(value, &m, sizeof value); }
};

}  // namespace

std::optional<LaneTracer> LaneTracer::create(const Scene& scene, const LightSet& lights,
                                             PathTracerSettings settings) {
  if (!lights.onlyUniformAreaLights()) return std::nullopt;
  const SceneData& data = scene.data();
  for (const SceneMesh& sm : data.meshes) {
    if (sm.alphaTested || sm.flatFrames.size() != sm.mesh.triangleCount()) return std::nullopt;
    for (const SceneMesh::FlatFrame& frame : sm.flatFrames)
      if (!frame.valid) return std::nullopt;
  }
  LaneTracer tracer(scene, lights, settings);
  for (const Material& material : data.materials) {
    const MaterialDesc& m = material.desc;
    const Bsdf* bsdf = material.uniformBsdf ? &*material.uniformBsdf : nullptr;
    if (!bsdf || !(bsdf->isPlainLambertian() || bsdf->scattersNothing()) || m.hasVolume ||
        m.emissiveTexture >= 0 || m.normalTexture >= 0 || material.alphaTested)
      return std::nullopt;
    const Vec3f up{0, 0, 1};
    const Rgb f = bsdf->isPlainLambertian() ? bsdf->evaluate(up, up).f : Rgb(0.0f);
    tracer.surfaces_.push_back(
        {bsdf->albedo(), f, m.isEmissive() ? m.emissive : Rgb(0.0f), m.doubleSided});
  }
  return tracer;
}

void LaneTracer::renderTile(const Tile& tile, const Sampling& sampling, const Camera& camera,
                            Film& film, PathTracer::RayCounts& rays, uint64_t& dropped) const {
  const SceneData& data = scene_->data();
  const int tileWidth = tile.x1 - tile.x0;
  const int pixelCount = tileWidth * (tile.y1 - tile.y0);
  int nextPixel = 0;

  // Per lane: its pixel, the sample being traced, the pixel's accumulators and its sampler.
  struct Lane {
    int x = 0, y = 0, sample = 0;
    PixelAccumulator pixel;
  };
  std::array<Lane, L::kWidth> lane;
  std::array<Sampler, L::kWidth> samplers{Sampler(sampling.seed), Sampler(sampling.seed),
                                          Sampler(sampling.seed), Sampler(sampling.seed)};
  Paths p{};
  Mask alive{};

  const auto startSample = [&](int i) {
    Lane& l = lane[size_t(i)];
    Sampler& sampler = samplers[size_t(i)];
    sampler.startPixelSample(l.x, l.y, uint32_t(l.sample / sampling.splits),
                             l.sample % sampling.splits);
    const Vec2f offset = sampler.getPixel2D();
    p.start(i, camera.generateRay({float(l.x) + offset.x, float(l.y) + offset.y}));
  };
  const auto takePixel = [&](int i) {
    if (nextPixel == pixelCount) {
      alive[i] = 0;
      return;
    }
    Lane& l = lane[size_t(i)];
    l.x = tile.x0 + nextPixel % tileWidth;
    l.y = tile.y0 + nextPixel / tileWidth;
    ++nextPixel;
    l.sample = 0;
    l.pixel = PixelAccumulator{};
    alive[i] = -1;
    startSample(i);
  };
  // The path of lane i has ended: accumulate it, then start the next sample or pixel.
  const auto finishPath = [&](int i) {
    Lane& l = lane[size_t(i)];
    if (!l.pixel.add(l.sample % sampling.splits, p.sample(i))) ++dropped;
    if (++l.sample < sampling.spp) return startSample(i);
    film.store(l.x, l.y, l.pixel);
    takePixel(i);
  };
  for (int i = 0; i < L::kWidth; ++i) takePixel(i);

  const Float inf = L::splat(std::numeric_limits<float>::infinity());
  while (L::any(alive)) {
    // Closest hits of the lanes' rays.
    std::array<uint32_t, L::kWidth> bounceDimensions{};
    RayPacket4 packet;
    for (int i = 0; i < L::kWidth; ++i) {
      if (!alive[i]) continue;
      bounceDimensions[size_t(i)] = samplers[size_t(i)].reserve(Sampler::kBounceDimensions);
      packet.ox[i] = p.origin.x[i], packet.oy[i] = p.origin.y[i], packet.oz[i] = p.origin.z[i];
      packet.dx[i] = p.direction.x[i], packet.dy[i] = p.direction.y[i];
      packet.dz[i] = p.direction.z[i], packet.tMax[i] = inf[i];
    }
    HitPacket4 hits;
    scene_->intersect4(LaneArray(alive).value, packet, &hits);
    rays.closestHit += uint64_t(countLanes(alive));

    // Gather what the hit lanes need; lanes that escaped record their features and end (no
    // environment emits in the scenes this tracer takes).
    Mask hit{}, ended{};
    L::Vec3 p0{}, p1{}, p2{}, ng{}, ns{}, tangent{}, surfaceAlbedo{}, f{}, emission{};
    Mask doubleSided{};
    Float u{}, v{}, t{};
    for (int i = 0; i < L::kWidth; ++i) {
      if (!alive[i]) continue;
      if (hits.geomID[i] == HitPacket4::kNoHit) {
        if (!p.locked[i]) {
          p.albedo.set(i, p.beta.rgbAt(i));
          p.normal.set(i, Vec3f{});
          p.featureDepth[i] = 0;
          p.locked[i] = -1;
          p.visibility[i] = 1;
        }
        ended[i] = -1;
        continue;
      }
      hit[i] = -1;
      const SceneMesh& sm = data.meshes[hits.geomID[i]];
      const uint32_t* idx = &sm.mesh.indices[3 * size_t(hits.primID[i])];
      p0.set(i, sm.mesh.positions[idx[0]]);
      p1.set(i, sm.mesh.positions[idx[1]]);
      p2.set(i, sm.mesh.positions[idx[2]]);
      const SceneMesh::FlatFrame& flat = sm.flatFrames[hits.primID[i]];
      ng.set(i, flat.geometricNormal);
      ns.set(i, flat.shadingNormal);
      tangent.set(i, flat.tangent);
      const Surface& s = surfaces_[size_t(sm.mesh.material)];
      surfaceAlbedo.set(i, s.albedo);
      f.set(i, s.f);
      emission.set(i, s.emission);
      doubleSided[i] = s.doubleSided ? -1 : 0;
      u[i] = hits.u[i], v[i] = hits.v[i], t[i] = hits.t[i];
    }

    // Scene::interaction for flat triangles.
    const Float b0 = 1.0f - u - v;
    const L::Vec3 position = p0 * b0 + p1 * u + p2 * v;
    const L::Vec3 positionError = barycentricPositionError(p0, p1, p2, b0, u, v);
    const Mask frontFace = L::dot(p.direction, ng) < 0.0f;
    const Float directionLength = L::length(p.direction);
    p.pathLength = L::select(hit, p.pathLength + t * directionLength, p.pathLength);

    // Emission found by the previous BSDF sample (or seen directly): rare, so lane by lane.
    const Mask emitting = hit & ~L::isBlack(emission) & (frontFace | doubleSided);
    for (int i = 0; i < L::kWidth && L::any(emitting); ++i) {
      if (!emitting[i]) continue;
      float w = 1.0f;
      if (!p.previousDelta[i]) {
        SurfaceInteraction si;
        si.position = position.at(i);
        si.geometricNormal = ng.at(i);
        si.geomID = hits.geomID[i];
        si.primID = hits.primID[i];
        w = chorus::render::powerHeuristic(p.previousPdf[i],
                                           lights_->pdfAreaLight(p.previousPosition.at(i), si));
      }
      p.radiance.set(i, p.radiance.rgbAt(i) + p.beta.rgbAt(i) * emission.rgbAt(i) * w);
    }

    // The shading frame, turned to the side the ray arrives on.
    const L::Vec3 wo = -(p.direction / directionLength);
    const Mask flip = L::dot(wo, ng) < 0.0f;
    ng = L::select(flip, -ng, ng);
    ns = L::select(flip, -ns, ns);
    LaneFrame frame{tangent, L::cross(ns, tangent), ns};
    L::Vec3 woLocal = frame.toLocal(wo);
    const Mask backFacing = hit & (woLocal.z < 1e-4f);
    for (int i = 0; i < L::kWidth && L::any(backFacing); ++i) {
      if (!backFacing[i]) continue;
      // A shading normal that faces away from the viewer: shade with the geometric one.
      const Frame g = Frame::fromZX(ng.at(i), tangent.at(i));
      frame.x.set(i, g.x), frame.y.set(i, g.y), frame.z.set(i, g.z);
      woLocal.set(i, g.toLocal(wo.at(i)));
    }

    const Mask record = hit & ~p.locked;
    p.albedo = L::select(record, p.beta * surfaceAlbedo, p.albedo);
    p.normal =
        L::select(record, L::select(L::dot(frame.z, wo) < 0.0f, -frame.z, frame.z), p.normal);
    p.featureDepth = L::select(record, p.pathLength, p.featureDepth);
    const Mask atMaxDepth = hit & (p.depth >= settings_.maxDepth);
    ended |= atMaxDepth;
    const Mask scatter = hit & ~atMaxDepth;

    // The vertex's sampler draws and light choice, lane by lane.
    Float uLobe{}, uDirX{}, uDirY{}, uLightX{}, uLightY{}, uRoulette{}, pmf{}, area{};
    L::Vec3 l0{}, l1{}, l2{}, lightNormal{}, lightLe{};
    Mask picked{}, lightDoubleSided{};
    for (int i = 0; i < L::kWidth; ++i) {
      if (!scatter[i]) continue;
      const Sampler::BounceDraws d = samplers[size_t(i)].getBounce(bounceDimensions[size_t(i)]);
      uLobe[i] = d.lobe, uDirX[i] = d.direction.x, uDirY[i] = d.direction.y;
      uLightX[i] = d.lightPoint.x, uLightY[i] = d.lightPoint.y, uRoulette[i] = d.roulette;
      float choicePmf = 0;
      const LightSet::AreaLight* light = lights_->pickAreaLight(d.light, &choicePmf);
      if (!light) continue;
      picked[i] = -1;
      pmf[i] = choicePmf;
      area[i] = light->area;
      l0.set(i, light->p0), l1.set(i, light->p1), l2.set(i, light->p2);
      lightNormal.set(i, light->normal);
      lightLe.set(i, light->Le);
      lightDoubleSided[i] = light->doubleSided ? -1 : 0;
    }

    // Next-event estimation (LightSet::sampleArea, then the BSDF and the shadow ray).
    const Mask half = uLightX < uLightY;
    const Float halfX = uLightX / 2.0f, halfY = uLightY / 2.0f;
    const Float lb0 = L::select(half, halfX, uLightX - halfY);
    const Float lb1 = L::select(half, uLightY - halfX, halfY);
    const Float lb2 = 1.0f - lb0 - lb1;
    const L::Vec3 pLight = l0 * lb0 + l1 * lb1 + l2 * lb2;
    const L::Vec3 toLight = pLight - position;
    const Float distanceSquared = L::dot(toLight, toLight);
    const L::Vec3 wi = toLight / L::sqrt(distanceSquared);
    const L::Vec3 Li =
        L::select(lightDoubleSided | (L::dot(wi, lightNormal) < 0.0f), lightLe, L::Vec3{});
    const Float cosLight = L::abs(L::dot(lightNormal, wi));
    const Float lightPdf = distanceSquared / (cosLight * area) * pmf;
    const Mask sampled = scatter & picked & (area > 0.0f) & (distanceSquared > 0.0f) &
                         (cosLight > 0.0f) & (distanceSquared / (cosLight * area) > 0.0f) &
                         ~L::isBlack(Li);
    const L::Vec3 wiLocal = frame.toLocal(wi);
    const Mask woAbove = L::dot(wo, ng) > 0.0f;
    const Mask sameSide = (L::dot(wi, ng) > 0.0f) == woAbove;
    const Mask evaluated =
        grazingSafe(woLocal) & grazingSafe(wiLocal) & ((woLocal.z < 0.0f) == (wiLocal.z < 0.0f));
    const L::Vec3 fCos = f * L::abs(wiLocal.z);
    const Mask shadow = sampled & sameSide & evaluated & ~L::isBlack(fCos);
    Mask lit{};
    if (L::any(shadow)) {
      const L::Vec3 from = offsetRayOrigin(position, positionError, ng, wi);
      const L::Vec3 to = offsetRayOrigin(
          pLight, barycentricPositionError(l0, l1, l2, lb0, lb1, lb2), lightNormal, -wi);
      const L::Vec3 span = to - from;
      RayPacket4 shadowRays;
      for (int i = 0; i < L::kWidth; ++i) {
        shadowRays.ox[i] = from.x[i], shadowRays.oy[i] = from.y[i], shadowRays.oz[i] = from.z[i];
        shadowRays.dx[i] = span.x[i], shadowRays.dy[i] = span.y[i], shadowRays.dz[i] = span.z[i];
        shadowRays.tMax[i] = 1.0f - kShadowEpsilon;
      }
      LaneArray blocked(Mask{});
      scene_->occluded4(LaneArray(shadow).value, shadowRays, blocked.value);
      rays.shadow += uint64_t(countLanes(shadow));
      Mask blockedLanes;
      std::memcpy(&blockedLanes, blocked.value, sizeof blockedLanes);
      lit = shadow & ~blockedLanes;
      const Float w = powerHeuristic(lightPdf, cosineHemispherePdf(L::abs(wiLocal.z)));
      p.radiance = L::select(lit, p.radiance + p.beta * fCos * Li * (w / lightPdf), p.radiance);
    }
    const Mask lockNow = scatter & ~p.locked;
    p.visibility = L::select(lockNow, L::select(lit, L::splat(1.0f), L::splat(0.0f)), p.visibility);
    p.locked |= lockNow;

    // Continue the paths by sampling the BSDF (Bsdf::sample for a plain Lambertian).
    L::Vec3 wiSampled = sampleCosineHemisphere(uDirX, uDirY);
    const Float bsdfPdf = cosineHemispherePdf(wiSampled.z);
    Mask continues = scatter & grazingSafe(woLocal) & L::isFinite(uLobe) & L::isFinite(uDirX) &
                     L::isFinite(uDirY) & grazingSafe(wiSampled) & (bsdfPdf > 0.0f) &
                     ~L::isBlack(f);
    wiSampled.z = L::select(woLocal.z < 0.0f, -wiSampled.z, wiSampled.z);
    const L::Vec3 wiWorld = frame.fromLocal(wiSampled);
    // Directions whose side of the geometric surface contradicts the lobe would leak light.
    continues &= (L::dot(wiWorld, ng) > 0.0f) == woAbove;
    const L::Vec3 beta = p.beta * (f * (L::abs(wiSampled.z) / bsdfPdf));
    const Mask roulette = continues & (p.depth + 1 >= settings_.rouletteStartDepth);
    const Float survive = L::min(L::splat(1.0f), L::maxComponent(beta));
    const Mask dies = roulette & ~(uRoulette < survive);
    continues &= ~dies;
    p.beta = L::select(continues, L::select(roulette, beta / survive, beta), p.beta);
    p.previousDelta &= ~continues;
    p.previousPdf = L::select(continues, bsdfPdf, p.previousPdf);
    p.previousPosition = L::select(continues, position, p.previousPosition);
    p.origin =
        L::select(continues, offsetRayOrigin(position, positionError, ng, wiWorld), p.origin);
    p.direction = L::select(continues, wiWorld, p.direction);
    p.depth -= continues;  // + 1 where the path goes on (masks are −1)
    ended |= scatter & ~continues;

    for (int i = 0; i < L::kWidth; ++i)
      if (ended[i]) finishPath(i);
  }
}

}  // namespace chorus::render
