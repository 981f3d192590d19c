#include "renderer/integrator/environment_light.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "renderer/sampling/warps.h"

namespace chorus::render {
namespace {

// Equirectangular mapping: θ from +Y (v = θ/π), φ = atan2(x, −z) (u = 1/2 + φ/2π).
Vec2f directionToUv(Vec3f d) {
  const float cosTheta = std::clamp(d.y, -1.0f, 1.0f);
  const float theta = std::acos(cosTheta);
  const float phi = std::atan2(d.x, -d.z);
  float u = 0.5f + phi * (0.5f * kInvPi);
  if (u >= 1.0f) u -= 1.0f;
  if (u < 0.0f) u += 1.0f;
  return {u, theta * kInvPi};
}

Vec3f uvToDirection(Vec2f uv, float* sinTheta) {
  const float theta = uv.y * kPi, phi = (uv.x - 0.5f) * 2.0f * kPi;
  *sinTheta = std::sin(theta);
  return {*sinTheta * std::sin(phi), std::cos(theta), -*sinTheta * std::cos(phi)};
}

}  // namespace

EnvironmentLight::EnvironmentLight(const EnvironmentDesc& desc)
    : kind_(desc.kind), scale_(std::max(0.0f, desc.intensity)) {
  const float radians = desc.rotationDegrees * kPi / 180.0f;
  cosRotation_ = std::cos(radians);
  sinRotation_ = std::sin(radians);
  if (kind_ == EnvironmentDesc::Kind::Constant) {
    constant_ = desc.radiance * scale_;
    meanLuminance_ = constant_.luminance();
    emits_ = constant_.maxComponent() > 0;
    return;
  }
  if (kind_ != EnvironmentDesc::Kind::Map || !desc.map) return;
  map_ = desc.map;
  const int w = map_->width(), h = map_->height();
  std::vector<float> f(size_t(w) * size_t(h));
  double weighted = 0, solidAngle = 0;
  for (int y = 0; y < h; ++y) {
    const float sinTheta = std::sin((float(y) + 0.5f) / float(h) * kPi);
    for (int x = 0; x < w; ++x) {
      const float lum = Rgb((*map_)(x, y, 0), (*map_)(x, y, 1), (*map_)(x, y, 2)).luminance();
      f[size_t(y) * size_t(w) + size_t(x)] = lum * sinTheta;
      weighted += double(lum) * sinTheta;
      solidAngle += sinTheta;
    }
  }
  meanLuminance_ = solidAngle > 0 ? float(weighted / solidAngle) * scale_ : 0.0f;
  emits_ = weighted > 0 && scale_ > 0;
  if (emits_) distribution_ = PiecewiseConstant2D(f, w, h);
}

Vec3f EnvironmentLight::toMap(Vec3f d) const {
  // Inverse of the rotation about +Y.
  return {cosRotation_ * d.x - sinRotation_ * d.z, d.y, sinRotation_ * d.x + cosRotation_ * d.z};
}

Vec3f EnvironmentLight::toWorld(Vec3f d) const {
  return {cosRotation_ * d.x + sinRotation_ * d.z, d.y, -sinRotation_ * d.x + cosRotation_ * d.z};
}

Rgb EnvironmentLight::texel(Vec2f uv) const {
  const int x = std::min(int(uv.x * float(map_->width())), map_->width() - 1);
  const int y = std::min(int(uv.y * float(map_->height())), map_->height() - 1);
  return Rgb((*map_)(x, y, 0), (*map_)(x, y, 1), (*map_)(x, y, 2)) * scale_;
}

Rgb EnvironmentLight::Le(const Vec3f& direction) const {
  return arrival(direction, false).Le;
}

EnvironmentLight::Arrival EnvironmentLight::arrival(const Vec3f& direction, bool withPdf) const {
  if (!emits_) return {};
  if (kind_ == EnvironmentDesc::Kind::Constant)
    return {constant_, withPdf ? kUniformSpherePdfSolidAngle : 0.0f};
  const Vec3f d = toMap(direction);
  const Vec2f uv = directionToUv(d);
  Arrival a{texel(uv), 0.0f};
  if (withPdf && !a.Le.isBlack()) a.pdfSolidAngle = mapPdf(d, uv);
  return a;
}

std::optional<EnvironmentLight::Sample> EnvironmentLight::sample(Vec2f u) const {
  if (!emits_) return std::nullopt;
  if (kind_ == EnvironmentDesc::Kind::Constant)
    return Sample{sampleUniformSphere(u), constant_, kUniformSpherePdfSolidAngle};
  float pdfUv = 0;
  const Vec2f uv = distribution_.sample(u, &pdfUv);
  float sinTheta = 0;
  const Vec3f dMap = uvToDirection(uv, &sinTheta);
  if (!(pdfUv > 0) || !(sinTheta > 0)) return std::nullopt;
  // dω = 2π² sin θ du dv.
  return Sample{toWorld(dMap), texel(uv), pdfUv / (2.0f * kPi * kPi * sinTheta)};
}

float EnvironmentLight::pdfSolidAngle(const Vec3f& direction) const {
  if (!emits_) return 0.0f;
  if (kind_ == EnvironmentDesc::Kind::Constant) return kUniformSpherePdfSolidAngle;
  const Vec3f d = toMap(direction);
  return mapPdf(d, directionToUv(d));
}

float EnvironmentLight::mapPdf(Vec3f d, Vec2f uv) const {
  const float sinTheta = std::sqrt(std::max(0.0f, 1.0f - d.y * d.y));
  if (!(sinTheta > 0)) return 0.0f;
  return distribution_.pdf(uv) / (2.0f * kPi * kPi * sinTheta);
}

float EnvironmentLight::power(float sceneRadius) const {
  return 4.0f * kPi * kPi * sceneRadius * sceneRadius * meanLuminance_;
}

}  // namespace chorus::render
