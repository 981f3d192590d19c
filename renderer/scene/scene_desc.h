#pragma once
// The parsed scene: plain data produced by loadGltf() (renderer/scene/gltf_loader.h), with no
// Embree or tinygltf types. Geometry is flattened to world space, one MeshDesc per (node,
// primitive) instance. buildScene() (renderer/scene/scene.h) turns it into the runtime Scene.
#include <cstdint>
#include <filesystem>
#include <limits>
#include <string>
#include <vector>

#include "renderer/math/vec.h"

namespace chorus::render {

struct Bounds3f {
  Vec3f min{std::numeric_limits<float>::infinity(), std::numeric_limits<float>::infinity(),
            std::numeric_limits<float>::infinity()};
  Vec3f max{-std::numeric_limits<float>::infinity(), -std::numeric_limits<float>::infinity(),
            -std::numeric_limits<float>::infinity()};

  bool empty() const { return !(min.x <= max.x && min.y <= max.y && min.z <= max.z); }
  void extend(Vec3f p) {
    min = render::min(min, p);
    max = render::max(max, p);
  }
  void extend(const Bounds3f& b) {
    if (b.empty()) return;
    extend(b.min);
    extend(b.max);
  }
  Vec3f center() const { return (min + max) * 0.5f; }
  Vec3f diagonal() const { return max - min; }
  // Radius of the bounding sphere around center() (0 for an empty box).
  float radius() const { return empty() ? 0.0f : 0.5f * length(diagonal()); }
};

// A decoded texture image, 8 bits per channel, always stored as RGBA (rows top to bottom).
struct ImageDesc {
  std::string name;  // uri, or "image <i>" for embedded images (for messages)
  int width = 0, height = 0;
  std::vector<uint8_t> rgba;
  // Mean of each channel in [0, 1], linear and sRGB-decoded (for light power estimates).
  float meanLinear[4] = {0, 0, 0, 0};
  float meanSrgbDecoded[4] = {0, 0, 0, 0};
};

enum class WrapMode { Repeat, ClampToEdge, MirroredRepeat };

struct TextureDesc {
  int image = -1;  // index into SceneDesc::images
  WrapMode wrapS = WrapMode::Repeat, wrapT = WrapMode::Repeat;
  bool nearest = false;  // magFilter NEAREST; otherwise bilinear
};

enum class AlphaMode { Opaque, Mask, Blend };

// A glTF material with the extensions chorus supports. Texture indices are into
// SceneDesc::textures, -1 when absent. Colours are linear.
struct MaterialDesc {
  std::string name;

  // pbrMetallicRoughness
  Rgb baseColor{1.0f};
  float alpha = 1.0f;
  int baseColorTexture = -1;  // sRGB RGB, linear A
  float metallic = 1.0f, roughness = 1.0f;
  int metallicRoughnessTexture = -1;  // B = metallic, G = roughness

  int normalTexture = -1;
  float normalScale = 1.0f;

  Rgb emissive{0.0f};  // emissiveFactor × KHR_materials_emissive_strength
  int emissiveTexture = -1;

  // KHR_materials_transmission, _ior, _specular, _volume
  float transmission = 0.0f;
  int transmissionTexture = -1;  // R
  float ior = 1.5f;
  float specular = 1.0f;
  int specularTexture = -1;  // A
  Rgb specularColor{1.0f};
  int specularColorTexture = -1;  // sRGB RGB
  bool hasVolume = false;         // thicknessFactor > 0: the surface bounds a solid
  Rgb attenuationColor{1.0f};
  float attenuationDistance = std::numeric_limits<float>::infinity();

  AlphaMode alphaMode = AlphaMode::Opaque;
  float alphaCutoff = 0.5f;
  bool doubleSided = false;

  bool isEmissive() const { return emissive.maxComponent() > 0; }
  bool isTransmissive() const { return transmission > 0; }
  // Whether any texture feeds the BSDF (the normal and emissive maps do not).
  bool hasBsdfTextures() const {
    return baseColorTexture >= 0 || metallicRoughnessTexture >= 0 || transmissionTexture >= 0 ||
           specularTexture >= 0 || specularColorTexture >= 0;
  }
  bool usesTextures() const {
    return hasBsdfTextures() || normalTexture >= 0 || emissiveTexture >= 0;
  }
};

// Four floats per vertex: tangent xyz and the bitangent sign w (glTF TANGENT convention:
// bitangent = cross(normal, tangent) · w).
struct Tangent {
  Vec3f xyz;
  float w = 1.0f;
};

// One triangle mesh in world space (a glTF primitive instanced by one node).
struct MeshDesc {
  std::string name;  // "node 'Box' mesh 2 primitive 0" (for messages)
  std::vector<Vec3f> positions;
  std::vector<Vec3f> normals;     // empty: flat shading with geometric normals
  std::vector<Vec2f> uvs;         // TEXCOORD_0; empty when absent
  std::vector<Tangent> tangents;  // empty unless a normal map needs them
  std::vector<uint32_t> indices;  // 3 per triangle, counter-clockwise = front
  int material = 0;               // index into SceneDesc::materials

  size_t triangleCount() const { return indices.size() / 3; }
};

enum class PunctualLightType { Point, Spot, Directional };

// KHR_lights_punctual. Intensity is used radiometrically, in the same units as emission:
// point/spot radiant intensity (W/sr), directional irradiance (W/m²).
struct PunctualLightDesc {
  std::string name;
  PunctualLightType type = PunctualLightType::Point;
  Rgb color{1.0f};
  float intensity = 1.0f;
  Vec3f position;
  Vec3f direction{0, 0, -1};  // world direction the light points to (spot, directional)
  float innerConeAngle = 0.0f, outerConeAngle = kPi / 4.0f;
};

enum class ProjectionType { Perspective, Orthographic };

struct CameraDesc {
  std::string name;
  ProjectionType projection = ProjectionType::Perspective;
  float yfov = kPi / 4.0f;         // perspective: vertical field of view, radians
  float aspectRatio = 0.0f;        // width / height; 0 when the file gives none
  float xmag = 1.0f, ymag = 1.0f;  // orthographic half-extents
  // Camera frame in world space (a glTF camera looks down its local −Z with +Y up), orthonormal.
  Vec3f position;
  Vec3f forward{0, 0, -1}, up{0, 1, 0}, right{1, 0, 0};
  // Thin lens (depth of field): radius of the lens disk in world units (0: a pinhole) and the
  // distance along `forward` of the plane in focus. glTF has no aperture: these come from the
  // render options (--lens-radius, --focus-distance).
  float lensRadius = 0.0f, focusDistance = 0.0f;
};

// The whole parsed scene.
struct SceneDesc {
  std::filesystem::path source;
  std::vector<MeshDesc> meshes;
  std::vector<MaterialDesc> materials;
  std::vector<TextureDesc> textures;
  std::vector<ImageDesc> images;
  std::vector<PunctualLightDesc> lights;
  std::vector<CameraDesc> cameras;  // in node order: cameras[0] is the first camera node
  Bounds3f bounds;
  std::vector<std::string> warnings;           // one line each, already formatted
  std::vector<std::string> ignoredExtensions;  // unsupported extensions the file uses

  size_t triangleCount() const {
    size_t n = 0;
    for (const MeshDesc& m : meshes) n += m.triangleCount();
    return n;
  }
};

}  // namespace chorus::render
