#pragma once
// The runtime scene: Embree device and BVH (RAII), the meshes as flat per-geomID arrays indexed
// by primID, materials with their textures, punctual lights, cameras and the environment.
// Built once from a SceneDesc by buildScene() (one rtcCommitScene), then read-only and safe to
// share between threads. Nothing here includes tinygltf; Embree types stay in scene.cpp.
#include <cstdint>
#include <limits>
#include <memory>
#include <optional>
#include <vector>

#include "renderer/integrator/bsdf.h"
#include "renderer/math/vec.h"
#include "renderer/scene/environment.h"
#include "renderer/scene/scene_desc.h"
#include "renderer/scene/texture.h"

namespace chorus::render {

struct Ray {
  Vec3f origin, direction;  // direction need not be unit length; t is in its units
  float tMax = std::numeric_limits<float>::infinity();
};

// What Embree reports for the closest hit.
struct Hit {
  float t = 0;
  uint32_t geomID = 0, primID = 0;
  float u = 0, v = 0;  // barycentrics of vertices 1 and 2
};

// Four rays for Embree's 4-wide packet queries, one per lane (structure of arrays).
struct RayPacket4 {
  alignas(16) float ox[4], oy[4], oz[4], dx[4], dy[4], dz[4], tMax[4];
};
// The closest hits of a RayPacket4; geomID[i] is kNoHit where lane i hit nothing.
struct HitPacket4 {
  static constexpr uint32_t kNoHit = ~0u;
  alignas(16) float t[4], u[4], v[4];
  alignas(16) uint32_t geomID[4], primID[4];
};

// Everything the integrator needs about a hit point.
struct SurfaceInteraction {
  Vec3f position;         // from the barycentrics (more accurate than origin + t · direction)
  Vec3f positionError;    // conservative bound on |position − exact point|, per axis
  Vec3f geometricNormal;  // unit; oriented to the side the interpolated vertex normals face
  Vec3f shadingNormal;    // unit; interpolated and normal-mapped, same side as geometricNormal
  Vec3f tangent;          // unit, ⟂ shadingNormal: frame = (tangent, n × tangent, n)
  Vec2f uv;
  bool frontFace = true;  // the ray arrived from the side geometricNormal points to
  int material = 0;
  uint32_t geomID = 0, primID = 0;
};

// One mesh as Embree geometry geomID: the scene's flat per-primitive arrays.
struct SceneMesh {
  MeshDesc mesh;  // world-space attributes; indices 3 per primID
  // Unit normal of each triangle from its winding ((0, 0, 1) when degenerate), computed once:
  // every hit and every light sample needs it.
  std::vector<Vec3f> faceNormals;
  // Triangles shaded flat (no vertex normals or three equal ones; no tangents or normal map):
  // their oriented geometric normal, shading normal and tangent, computed once. Per hit, the
  // normalisation of the interpolated normal and the frame's divisions were a chain of
  // dependent divisions, about half of interaction()'s time. Empty when no triangle qualifies.
  struct FlatFrame {
    Vec3f geometricNormal, shadingNormal, tangent;
    bool valid = false;
  };
  std::vector<FlatFrame> flatFrames;  // by primID
  int firstAreaLight = -1;            // area light index of primID 0 when the material emits
  bool alphaTested = false;
};

struct Material {
  MaterialDesc desc;
  bool alphaTested = false;  // MASK, or BLEND with coverage below 1 somewhere
  // The BSDF of every point, built once when no texture varies it (most materials of
  // authored scenes): constructing one per hit was a few percent of the render.
  std::optional<Bsdf> uniformBsdf;
};

// Shared, immutable scene data (heap-allocated so Embree callbacks can point into it).
struct SceneData {
  std::filesystem::path source;
  std::vector<SceneMesh> meshes;  // index = geomID
  std::vector<Material> materials;
  std::vector<ImageDesc> images;
  std::vector<Texture> textures;  // point into images
  std::vector<PunctualLightDesc> punctualLights;
  std::vector<CameraDesc> cameras;
  EnvironmentDesc environment;
  Bounds3f bounds;
  size_t triangleCount = 0;
  size_t areaLightCount = 0;  // emissive triangles
};

class Scene {
 public:
  Scene(Scene&&) noexcept;
  Scene& operator=(Scene&&) noexcept;
  ~Scene();

  // Closest hit along the ray within (0, ray.tMax], or false.
  bool intersect(const Ray& ray, Hit* hit, bool coherent = false) const;
  // Whether anything blocks the segment (0, tMax) along direction.
  bool occluded(const Vec3f& origin, const Vec3f& direction, float tMax) const;
  // The same queries for the lanes i with active[i] = −1 (others are left alone): the hits
  // equal intersect()'s; blocked[i] = −1 where occluded() would return true, else 0.
  void intersect4(const int32_t active[4], const RayPacket4& rays, HitPacket4* hits) const;
  void occluded4(const int32_t active[4], const RayPacket4& rays, int32_t blocked[4]) const;

  SurfaceInteraction interaction(const Hit& hit, const Vec3f& rayDirection) const;
  MaterialPoint materialPoint(const SurfaceInteraction& si) const;
  // Radiance emitted toward −rayDirection (zero behind single-sided emitters).
  Rgb emitted(const SurfaceInteraction& si) const;

  // A point on an emissive triangle (barycentrics b1, b2 of vertices 1 and 2) seen along
  // `direction` (from the receiver toward the point): the light-sampling counterpart of
  // interaction() + emitted(), without the shading frame.
  struct EmitterPoint {
    Vec3f position, positionError, geometricNormal;
    Rgb Le;
  };
  EmitterPoint emitterPoint(uint32_t geomID, uint32_t primID, float b1, float b2,
                            const Vec3f& direction) const;

  const SceneData& data() const { return *data_; }
  const Material& material(int index) const { return data_->materials[size_t(index)]; }
  const Bounds3f& bounds() const { return data_->bounds; }
  const EnvironmentDesc& environment() const { return data_->environment; }
  // True when the scene had no light at all and buildScene() added the default white
  // environment.
  bool usesDefaultEnvironment() const { return defaultEnvironment_; }

 private:
  friend Scene buildScene(SceneDesc desc, EnvironmentDesc environment);
  struct Embree;
  Scene();

  std::unique_ptr<SceneData> data_;
  std::unique_ptr<Embree> embree_;
  bool defaultEnvironment_ = false;
};

// Builds the runtime scene (takes ownership of the desc's arrays). With no emissive material,
// no punctual light and no environment, the environment becomes a uniform white radiance of 1
// (see Scene::usesDefaultEnvironment). Throws chorus::Error for an environment
// checkEnvironment() rejects, or when Embree fails.
Scene buildScene(SceneDesc desc, EnvironmentDesc environment);

}  // namespace chorus::render
