#pragma once
// Material evaluation at a surface point: factors × texture lookups → the BSDF's MaterialPoint,
// emitted radiance, coverage (alpha) and the normal-mapped shading normal. Texture lookups
// happen only for the slots a material actually uses.
#include <span>

#include "renderer/integrator/bsdf.h"
#include "renderer/scene/scene_desc.h"
#include "renderer/scene/texture.h"

namespace chorus::render {

MaterialPoint evaluateMaterial(const MaterialDesc& m, std::span<const Texture> textures, Vec2f uv);

// Emitted radiance toward the side the surface faces (emissiveFactor × strength × texture).
Rgb evaluateEmission(const MaterialDesc& m, std::span<const Texture> textures, Vec2f uv);

// Coverage: baseColorFactor.a × baseColorTexture.a.
float evaluateAlpha(const MaterialDesc& m, std::span<const Texture> textures, Vec2f uv);

// The shading normal after the normal map (glTF: n = normalize((2 t − 1) · (s, s, 1)) in the
// tangent frame (tangent, bitangent, normal)). Returns `frame.z` when the material has none.
Vec3f applyNormalMap(const MaterialDesc& m, std::span<const Texture> textures, Vec2f uv,
                     const Frame& tangentFrame);

// Whether a surface needs the alpha test (MASK, or BLEND with some coverage below 1).
bool needsAlphaTest(const MaterialDesc& m);

}  // namespace chorus::render
