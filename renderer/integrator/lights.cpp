#include "renderer/integrator/lights.h"

#include <algorithm>
#include <cmath>

#include "renderer/integrator/ray_offset.h"
#include "renderer/sampling/warps.h"

namespace chorus::render {
namespace {

// Mean emitted radiance of a material (its emissive texture averaged over the image).
Rgb meanEmission(const MaterialDesc& m, const SceneData& data) {
  if (m.emissiveTexture < 0) return m.emissive;
  const ImageDesc& image = data.textures[size_t(m.emissiveTexture)].image();
  return m.emissive *
         Rgb(image.meanSrgbDecoded[0], image.meanSrgbDecoded[1], image.meanSrgbDecoded[2]);
}

// The side every point of a triangle faces, when it is the same everywhere: the face normal
// turned toward the vertex normals (Scene::interaction's rule), which cannot change across the
// triangle when all three vertex normals lie on one side of it. Zero otherwise.
Vec3f uniformOrientation(const SceneMesh& sm, uint32_t primID) {
  const Vec3f ng = sm.faceNormals[primID];
  if (sm.mesh.normals.empty()) return ng;
  const uint32_t* idx = &sm.mesh.indices[3 * size_t(primID)];
  int front = 0, back = 0;
  for (int v = 0; v < 3; ++v) {
    const float d = dot(sm.mesh.normals[idx[v]], ng);
    front += d > 0;
    back += d < 0;
  }
  return front == 3 ? ng : back == 3 ? -ng : Vec3f{};
}

// glTF KHR_lights_punctual spot falloff: a smooth step between the outer and inner cone,
// squared (the extension's recommended implementation).
float spotAttenuation(const PunctualLightDesc& light, Vec3f wi) {
  const float cosOuter = std::cos(light.outerConeAngle);
  const float cosInner = std::cos(light.innerConeAngle);
  const float scale = 1.0f / std::max(1e-3f, cosInner - cosOuter);
  const float cd = dot(light.direction, -wi);
  const float a = std::clamp((cd - cosOuter) * scale, 0.0f, 1.0f);
  return a * a;
}

float punctualPower(const PunctualLightDesc& light, float sceneRadius) {
  const float I = light.intensity * light.color.luminance();
  switch (light.type) {
    case PunctualLightType::Point:
      return 4.0f * kPi * I;
    case PunctualLightType::Spot: {
      const float cosMean =
          0.5f * (std::cos(light.innerConeAngle) + std::cos(light.outerConeAngle));
      return 2.0f * kPi * I * (1.0f - cosMean);
    }
    case PunctualLightType::Directional:
    default:
      return kPi * sceneRadius * sceneRadius * I;
  }
}

}  // namespace

LightSet::LightSet(const Scene& scene) : scene_(&scene), environment_(scene.environment()) {
  const SceneData& data = scene.data();
  const float radius = std::max(data.bounds.radius(), 1e-6f);
  std::vector<float> power;

  for (size_t geomID = 0; geomID < data.meshes.size(); ++geomID) {
    const SceneMesh& sm = data.meshes[geomID];
    if (sm.firstAreaLight < 0) continue;
    const MaterialDesc& m = data.materials[size_t(sm.mesh.material)].desc;
    const Rgb meanLe = meanEmission(m, data);
    const float sides = m.doubleSided ? 2.0f : 1.0f;
    for (uint32_t primID = 0; primID < sm.mesh.triangleCount(); ++primID) {
      AreaLight light;
      light.geomID = uint32_t(geomID);
      light.primID = primID;
      const uint32_t* idx = &sm.mesh.indices[3 * size_t(primID)];
      light.p0 = sm.mesh.positions[idx[0]];
      light.p1 = sm.mesh.positions[idx[1]];
      light.p2 = sm.mesh.positions[idx[2]];
      light.area = 0.5f * length(cross(light.p1 - light.p0, light.p2 - light.p0));
      light.normal = uniformOrientation(sm, primID);
      light.uniform = m.emissiveTexture < 0 && lengthSquared(light.normal) > 0;
      light.doubleSided = m.doubleSided;
      light.Le = m.emissive;
      areaLights_.push_back(light);
      lights_.push_back({Kind::Area, uint32_t(areaLights_.size() - 1)});
      power.push_back(kPi * sides * light.area * meanLe.luminance());
    }
  }
  for (size_t i = 0; i < data.punctualLights.size(); ++i) {
    lights_.push_back({Kind::Punctual, uint32_t(i)});
    power.push_back(punctualPower(data.punctualLights[i], radius));
  }
  if (environment_.emits()) {
    environmentIndex_ = int(lights_.size());
    lights_.push_back({Kind::Environment, 0});
    power.push_back(environment_.power(radius));
  }

  double total = 0;
  for (float& p : power) {
    if (!(p > 0) || !std::isfinite(p)) p = 0;
    total += p;
  }
  if (!(total > 0)) {
    lights_.clear();
    environmentIndex_ = -1;
    return;
  }
  choice_ = AliasTable(power);
}

LightSet::Pick LightSet::pick(float uChoice) const {
  Pick p;
  if (lights_.empty()) return p;
  p.index = choice_.sample(uChoice, &p.pmf);
  const LightRef light = lights_[size_t(p.index)];
  if (light.kind == Kind::Area && areaLights_[light.index].uniform)
    p.uniformArea = &areaLights_[light.index];
  return p;
}

std::optional<LightSample> LightSet::sample(const Vec3f& ref, const Pick& pick, Vec2f u) const {
  if (!(pick.pmf > 0)) return std::nullopt;
  const float pmf = pick.pmf;
  const LightRef light = lights_[size_t(pick.index)];
  // Filled in place and returned as the one named object (no copies of the ~70-byte sample).
  std::optional<LightSample> s(std::in_place);
  bool found = false;
  switch (light.kind) {
    case Kind::Area:
      found = sampleArea(areaLights_[light.index], ref, u, *s);
      break;
    case Kind::Punctual:
      found = samplePunctual(scene_->data().punctualLights[light.index], ref, *s);
      break;
    case Kind::Environment:
      if (const auto e = environment_.sample(u)) {
        s->Li = e->Le;
        s->wi = e->wi;
        s->pdf = e->pdfSolidAngle;
        s->isInfinite = true;
        found = true;
      }
      break;
  }
  if (!found || !(s->pdf > 0) || s->Li.isBlack())
    s.reset();
  else
    s->pdf *= pmf;
  return s;
}

bool LightSet::sampleArea(const AreaLight& light, const Vec3f& ref, Vec2f u, LightSample& s) const {
  if (!(light.area > 0)) return false;
  const Vec2f b = sampleUniformTriangle(u);
  const float b2 = 1 - b.x - b.y;
  const Vec3f p = light.p0 * b.x + light.p1 * b.y + light.p2 * b2;
  const Vec3f toLight = p - ref;
  const float distanceSquared = lengthSquared(toLight);
  if (!(distanceSquared > 0)) return false;
  const Vec3f wi = toLight / std::sqrt(distanceSquared);
  if (light.uniform) {
    s.nLight = light.normal;
    if (light.doubleSided || dot(wi, light.normal) < 0) s.Li = light.Le;
  } else {
    const Scene::EmitterPoint e = scene_->emitterPoint(light.geomID, light.primID, b.y, b2, wi);
    s.nLight = e.geometricNormal;
    s.Li = e.Le;
  }
  const float cosLight = std::abs(dot(s.nLight, wi));
  if (!(cosLight > 0)) return false;
  s.wi = wi;
  s.pdf = distanceSquared / (cosLight * light.area);
  s.pLight = p;
  s.pLightError = barycentricPositionError(light.p0, light.p1, light.p2, b.x, b.y, b2);
  return true;
}

bool LightSet::samplePunctual(const PunctualLightDesc& light, const Vec3f& ref,
                              LightSample& s) const {
  s.isDelta = true;
  s.pdf = 1.0f;
  if (light.type == PunctualLightType::Directional) {
    s.wi = -light.direction;
    s.Li = light.color * light.intensity;
    s.isInfinite = true;
    return true;
  }
  const Vec3f toLight = light.position - ref;
  const float distanceSquared = lengthSquared(toLight);
  if (!(distanceSquared > 0)) return false;
  s.wi = toLight / std::sqrt(distanceSquared);
  s.Li = light.color * (light.intensity / distanceSquared);
  if (light.type == PunctualLightType::Spot) s.Li *= spotAttenuation(light, s.wi);
  s.pLight = light.position;
  return true;
}

float LightSet::pdfAreaLight(const Vec3f& ref, const SurfaceInteraction& lightPoint) const {
  if (lights_.empty()) return 0.0f;
  const SceneMesh& sm = scene_->data().meshes[lightPoint.geomID];
  if (sm.firstAreaLight < 0) return 0.0f;
  const size_t index = size_t(sm.firstAreaLight) + lightPoint.primID;
  const AreaLight& light = areaLights_[index];
  const Vec3f toLight = lightPoint.position - ref;
  const float distanceSquared = lengthSquared(toLight);
  const float cosLight =
      std::abs(dot(lightPoint.geometricNormal, toLight)) / std::sqrt(distanceSquared);
  if (!(cosLight > 0) || !(light.area > 0)) return 0.0f;
  return choice_.pmf(int(index)) * distanceSquared / (cosLight * light.area);
}

EnvironmentLight::Arrival LightSet::environmentArrival(const Vec3f& direction, bool withPdf) const {
  const bool sampled = environmentIndex_ >= 0;
  EnvironmentLight::Arrival a = environment_.arrival(direction, withPdf && sampled);
  if (sampled) a.pdfSolidAngle *= choice_.pmf(environmentIndex_);
  return a;
}

}  // namespace chorus::render
