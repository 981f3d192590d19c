#include "renderer/scene/material_eval.h"

#include <algorithm>

namespace chorus::render {

MaterialPoint evaluateMaterial(const MaterialDesc& m, std::span<const Texture> textures, Vec2f uv) {
  MaterialPoint p;
  p.baseColor = m.baseColor;
  p.metallic = m.metallic;
  p.roughness = m.roughness;
  if (m.baseColorTexture >= 0) {
    const auto t = textures[size_t(m.baseColorTexture)].sample(uv, ColorEncoding::Srgb);
    p.baseColor *= Rgb(t[0], t[1], t[2]);
  }
  if (m.metallicRoughnessTexture >= 0) {
    const auto t = textures[size_t(m.metallicRoughnessTexture)].sample(uv, ColorEncoding::Linear);
    p.roughness *= t[1];
    p.metallic *= t[2];
  }
  p.ior = m.ior;
  p.transmission = m.transmission;
  if (m.transmissionTexture >= 0)
    p.transmission *= textures[size_t(m.transmissionTexture)].sample(uv, ColorEncoding::Linear)[0];
  p.specular = m.specular;
  if (m.specularTexture >= 0)
    p.specular *= textures[size_t(m.specularTexture)].sample(uv, ColorEncoding::Linear)[3];
  p.specularColor = m.specularColor;
  if (m.specularColorTexture >= 0) {
    const auto t = textures[size_t(m.specularColorTexture)].sample(uv, ColorEncoding::Srgb);
    p.specularColor *= Rgb(t[0], t[1], t[2]);
  }
  p.thinWalled = !m.hasVolume;
  return p;
}

Rgb evaluateEmission(const MaterialDesc& m, std::span<const Texture> textures, Vec2f uv) {
  Rgb e = m.emissive;
  if (m.emissiveTexture >= 0) {
    const auto t = textures[size_t(m.emissiveTexture)].sample(uv, ColorEncoding::Srgb);
    e *= Rgb(t[0], t[1], t[2]);
  }
  return e;
}

float evaluateAlpha(const MaterialDesc& m, std::span<const Texture> textures, Vec2f uv) {
  float a = m.alpha;
  if (m.baseColorTexture >= 0)
    a *= textures[size_t(m.baseColorTexture)].sample(uv, ColorEncoding::Linear)[3];
  return a;
}

Vec3f applyNormalMap(const MaterialDesc& m, std::span<const Texture> textures, Vec2f uv,
                     const Frame& tangentFrame) {
  if (m.normalTexture < 0) return tangentFrame.z;
  const auto t = textures[size_t(m.normalTexture)].sample(uv, ColorEncoding::Linear);
  const Vec3f local{(2 * t[0] - 1) * m.normalScale, (2 * t[1] - 1) * m.normalScale, 2 * t[2] - 1};
  const Vec3f n = tangentFrame.fromLocal(local);
  const float len = length(n);
  return len > 0 && std::isfinite(len) ? n / len : tangentFrame.z;
}

bool needsAlphaTest(const MaterialDesc& m) {
  if (m.alphaMode == AlphaMode::Mask) return true;
  return m.alphaMode == AlphaMode::Blend && (m.alpha < 1 || m.baseColorTexture >= 0);
}

}  // namespace chorus::render
