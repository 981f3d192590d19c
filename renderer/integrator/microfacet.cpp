#include "renderer/integrator/microfacet.h"

#include <cmath>

namespace chorus::render {

namespace {
// Below this the lobe is sharper than float precision resolves directions anyway.
constexpr float kMinAlpha = 1e-4f;
}  // namespace

GgxDistribution::GgxDistribution(float alpha) : alpha_(std::max(alpha, kMinAlpha)) {}

float GgxDistribution::D(Vec3f h) const {
  if (h.z <= 0) return 0;
  // D = 1 / (π α² (h.x²/α² + h.y²/α² + h.z²)²), which stays finite for tiny α.
  const float a2 = alpha_ * alpha_;
  const float t = (h.x * h.x + h.y * h.y) / a2 + h.z * h.z;
  return 1.0f / (kPi * a2 * t * t);
}

float GgxDistribution::lambda(Vec3f w) const {
  const float cos2 = w.z * w.z;
  const float sin2 = std::max(0.0f, w.x * w.x + w.y * w.y);
  if (cos2 == 0) return sin2 > 0 ? INFINITY : 0.0f;
  const float alpha2Tan2 = alpha_ * alpha_ * sin2 / cos2;
  return 0.5f * (std::sqrt(1.0f + alpha2Tan2) - 1.0f);
}

float GgxDistribution::visibleNormalPdf(Vec3f w, Vec3f h) const {
  if (w.z <= 0) return 0;
  const float wh = dot(w, h);
  if (wh <= 0) return 0;
  return G1(w) * wh * D(h) / w.z;
}

Vec3f GgxDistribution::sampleVisibleNormal(Vec3f w, Vec2f u) const {
  // Heitz 2018, listing 1: stretch the view direction to the configuration where α = 1 ...
  const Vec3f wh = normalize(Vec3f(alpha_ * w.x, alpha_ * w.y, w.z));
  // ... build a frame around it ...
  const float lenSq = wh.x * wh.x + wh.y * wh.y;
  const Vec3f t1 = lenSq > 0 ? Vec3f(-wh.y, wh.x, 0) / std::sqrt(lenSq) : Vec3f(1, 0, 0);
  const Vec3f t2 = cross(wh, t1);
  // ... sample the projected hemisphere: a disk whose far half is squashed by the view angle ...
  const float r = std::sqrt(u.x);
  const float phi = 2.0f * kPi * u.y;
  const float p1 = r * std::cos(phi);
  float p2 = r * std::sin(phi);
  const float s = 0.5f * (1.0f + wh.z);
  p2 = (1.0f - s) * std::sqrt(std::max(0.0f, 1.0f - p1 * p1)) + s * p2;
  // ... lift to the hemisphere and unstretch.
  const Vec3f nh = t1 * p1 + t2 * p2 + wh * std::sqrt(std::max(0.0f, 1.0f - p1 * p1 - p2 * p2));
  return normalize(Vec3f(alpha_ * nh.x, alpha_ * nh.y, std::max(1e-6f, nh.z)));
}

}  // namespace chorus::render
