#include "renderer/scene/scene.h"

#include <embree3/rtcore.h>

#include <cmath>
#include <cstring>
#include <string>

#include "common/error.h"
#include "renderer/integrator/ray_offset.h"
#include "renderer/scene/material_eval.h"

namespace chorus::render {

// What the alpha-test filter needs about one geometry.
struct AlphaTestContext {
  const SceneMesh* mesh = nullptr;
  const MaterialDesc* material = nullptr;
  const std::vector<Texture>* textures = nullptr;
};

struct Scene::Embree {
  RTCDevice device = nullptr;
  RTCScene scene = nullptr;
  std::string firstError;
  std::vector<AlphaTestContext> alphaContexts;  // sized once, so pointers stay valid

  ~Embree() {
    if (scene) rtcReleaseScene(scene);
    if (device) rtcReleaseDevice(device);
  }
};

namespace {

void embreeError(void* user, RTCError code, const char* message) {
  auto* embree = static_cast<std::string*>(user);
  if (embree->empty())
    *embree = "Embree error " + std::to_string(int(code)) + ": " + (message ? message : "");
}

// A uniform number in [0, 1) from the ray and the hit, so that stochastic coverage (alphaMode
// BLEND) is deterministic: the same ray always sees the same surfaces.
float hashToUnit(float a, float b, float c, uint32_t d) {
  uint64_t h = 0x9E3779B97F4A7C15ull;
  for (float f : {a, b, c}) {
    uint32_t bits;
    std::memcpy(&bits, &f, 4);
    h ^= bits;
    h *= 0xFF51AFD7ED558CCDull;
    h ^= h >> 33;
  }
  h ^= d;
  h *= 0xC4CEB9FE1A85EC53ull;
  h ^= h >> 33;
  return float(h >> 40) * (1.0f / 16777216.0f);
}

Vec2f interpolateUv(const MeshDesc& mesh, uint32_t primID, float u, float v) {
  if (mesh.uvs.empty()) return {0, 0};
  const uint32_t* idx = &mesh.indices[3 * size_t(primID)];
  return mesh.uvs[idx[0]] * (1 - u - v) + mesh.uvs[idx[1]] * u + mesh.uvs[idx[2]] * v;
}

// Embree filter for alpha-tested geometry: MASK rejects coverage below the cutoff; BLEND keeps a
// hit with probability equal to its coverage (stochastic transparency, unbiased on average).
void alphaTestFilter(const RTCFilterFunctionNArguments* args) {
  const auto* ctx = static_cast<const AlphaTestContext*>(args->geometryUserPtr);
  for (unsigned i = 0; i < args->N; ++i) {
    if (args->valid[i] == 0) continue;
    const uint32_t primID = RTCHitN_primID(args->hit, args->N, i);
    const float u = RTCHitN_u(args->hit, args->N, i), v = RTCHitN_v(args->hit, args->N, i);
    const Vec2f uv = interpolateUv(ctx->mesh->mesh, primID, u, v);
    const float alpha = evaluateAlpha(*ctx->material, *ctx->textures, uv);
    bool keep;
    if (ctx->material->alphaMode == AlphaMode::Mask) {
      keep = alpha >= ctx->material->alphaCutoff;
    } else {
      const float x = RTCRayN_org_x(args->ray, args->N, i) + RTCRayN_dir_x(args->ray, args->N, i);
      const float y = RTCRayN_org_y(args->ray, args->N, i) + RTCRayN_dir_y(args->ray, args->N, i);
      const float z = RTCRayN_org_z(args->ray, args->N, i) + RTCRayN_dir_z(args->ray, args->N, i);
      keep = hashToUnit(x + u, y + v, z, primID) < alpha;
    }
    if (!keep) args->valid[i] = 0;
  }
}

// Alpha testing is needed unless the coverage can never fall below what the mode keeps.
bool materialNeedsAlphaTest(const MaterialDesc& m, const std::vector<TextureDesc>& textures,
                            const std::vector<ImageDesc>& images) {
  if (!needsAlphaTest(m)) return false;
  bool textureOpaque = true;
  if (m.baseColorTexture >= 0) {
    const ImageDesc& image = images[size_t(textures[size_t(m.baseColorTexture)].image)];
    textureOpaque = image.meanLinear[3] >= 1.0f;
  }
  const float threshold = m.alphaMode == AlphaMode::Mask ? m.alphaCutoff : 1.0f;
  return !(textureOpaque && m.alpha >= threshold);
}

Vec3f faceNormal(const MeshDesc& mesh, uint32_t primID) {
  const uint32_t* idx = &mesh.indices[3 * size_t(primID)];
  const Vec3f& p0 = mesh.positions[idx[0]];
  const Vec3f ng = cross(mesh.positions[idx[1]] - p0, mesh.positions[idx[2]] - p0);
  const float ngLength = length(ng);
  return ngLength > 0 ? ng / ngLength : Vec3f{0, 0, 1};
}

// The unit geometric normal of a triangle, turned to the side its vertex normals face (the
// authored normals define the outside; the winding may disagree). *shadingNormal receives the
// interpolated vertex normal (the geometric normal without usable vertex normals). Positions are
// read here rather than passed as Vec3f arguments: 12-byte structs passed by value cost
// store-forwarding stalls on x86-64.
inline Vec3f orientedGeometricNormal(const SceneMesh& sm, uint32_t primID, const uint32_t* idx,
                                     float b0, float b1, float b2, Vec3f* shadingNormal) {
  const MeshDesc& mesh = sm.mesh;
  Vec3f ng = sm.faceNormals[primID];
  *shadingNormal = ng;
  if (!mesh.normals.empty()) {
    const Vec3f n =
        mesh.normals[idx[0]] * b0 + mesh.normals[idx[1]] * b1 + mesh.normals[idx[2]] * b2;
    const float len = length(n);
    if (len > 1e-6f && std::isfinite(len)) {
      *shadingNormal = n / len;
      if (dot(*shadingNormal, ng) < 0) ng = -ng;
    }
  }
  return ng;
}

// SceneMesh::flatFrames: what interaction() computes for a flat triangle, at vertex 0 (the
// interpolated normal is then the shared one exactly; elsewhere it may differ in its last bit).
std::vector<SceneMesh::FlatFrame> flatFrames(const SceneMesh& sm, const MaterialDesc& material) {
  const MeshDesc& mesh = sm.mesh;
  if (!mesh.tangents.empty() || (material.normalTexture >= 0 && !mesh.uvs.empty())) return {};
  const auto same = [](const Vec3f& a, const Vec3f& b) {
    return a.x == b.x && a.y == b.y && a.z == b.z;
  };
  std::vector<SceneMesh::FlatFrame> frames(mesh.triangleCount());
  bool any = false;
  for (uint32_t primID = 0; primID < frames.size(); ++primID) {
    const uint32_t* idx = &mesh.indices[3 * size_t(primID)];
    if (!mesh.normals.empty() && !(same(mesh.normals[idx[0]], mesh.normals[idx[1]]) &&
                                   same(mesh.normals[idx[0]], mesh.normals[idx[2]])))
      continue;
    Vec3f ns;
    const Vec3f ng = orientedGeometricNormal(sm, primID, idx, 1.0f, 0.0f, 0.0f, &ns);
    const Frame frame = Frame::fromZ(ns);
    frames[primID] = {ng, frame.z, frame.x, true};
    any = true;
  }
  if (!any) return {};
  return frames;
}

}  // namespace

Scene::Scene() : data_(std::make_unique<SceneData>()), embree_(std::make_unique<Embree>()) {}
Scene::Scene(Scene&&) noexcept = default;
Scene& Scene::operator=(Scene&&) noexcept = default;
Scene::~Scene() = default;

Scene buildScene(SceneDesc desc, EnvironmentDesc environment) {
  checkEnvironment(environment);
  Scene scene;
  SceneData& data = *scene.data_;
  data.source = desc.source;
  data.images = std::move(desc.images);
  data.textures.reserve(desc.textures.size());
  for (const TextureDesc& t : desc.textures)
    data.textures.emplace_back(data.images[size_t(t.image)], t);
  for (const MaterialDesc& m : desc.materials) {
    data.materials.push_back({m, materialNeedsAlphaTest(m, desc.textures, data.images), {}});
    if (!m.hasBsdfTextures())
      data.materials.back().uniformBsdf.emplace(evaluateMaterial(m, data.textures, Vec2f{0, 0}));
  }
  data.punctualLights = std::move(desc.lights);
  data.cameras = std::move(desc.cameras);
  data.bounds = desc.bounds;
  data.meshes.reserve(desc.meshes.size());
  for (MeshDesc& m : desc.meshes) {
    SceneMesh sm;
    sm.mesh = std::move(m);
    sm.faceNormals.resize(sm.mesh.triangleCount());
    for (uint32_t primID = 0; primID < sm.faceNormals.size(); ++primID)
      sm.faceNormals[primID] = faceNormal(sm.mesh, primID);
    const Material& material = data.materials[size_t(sm.mesh.material)];
    sm.flatFrames = flatFrames(sm, material.desc);
    sm.alphaTested = material.alphaTested;
    if (material.desc.isEmissive()) {
      sm.firstAreaLight = int(data.areaLightCount);
      data.areaLightCount += sm.mesh.triangleCount();
    }
    data.triangleCount += sm.mesh.triangleCount();
    data.meshes.push_back(std::move(sm));
  }

  if (environment.kind == EnvironmentDesc::Kind::None && data.areaLightCount == 0 &&
      data.punctualLights.empty()) {
    environment = EnvironmentDesc::constant(Rgb(1.0f));
    scene.defaultEnvironment_ = true;
  }
  data.environment = std::move(environment);

  Scene::Embree& embree = *scene.embree_;
  embree.device = rtcNewDevice(nullptr);
  if (!embree.device) throw Error("cannot create the Embree device");
  rtcSetDeviceErrorFunction(embree.device, embreeError, &embree.firstError);
  embree.scene = rtcNewScene(embree.device);
  // Robust (watertight) traversal: no rays slipping through shared edges of closed meshes.
  rtcSetSceneFlags(embree.scene, RTC_SCENE_FLAG_ROBUST);
  rtcSetSceneBuildQuality(embree.scene, RTC_BUILD_QUALITY_HIGH);
  embree.alphaContexts.resize(data.meshes.size());
  for (size_t geomID = 0; geomID < data.meshes.size(); ++geomID) {
    const SceneMesh& sm = data.meshes[geomID];
    RTCGeometry geometry = rtcNewGeometry(embree.device, RTC_GEOMETRY_TYPE_TRIANGLE);
    auto* vertices = static_cast<float*>(
        rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                3 * sizeof(float), sm.mesh.positions.size()));
    auto* indices = static_cast<uint32_t*>(
        rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                3 * sizeof(uint32_t), sm.mesh.triangleCount()));
    if (!vertices || !indices) {
      rtcReleaseGeometry(geometry);
      throw Error(embree.firstError.empty() ? "Embree could not allocate geometry buffers"
                                            : embree.firstError);
    }
    std::memcpy(vertices, sm.mesh.positions.data(), sm.mesh.positions.size() * sizeof(Vec3f));
    std::memcpy(indices, sm.mesh.indices.data(), sm.mesh.indices.size() * sizeof(uint32_t));
    if (sm.alphaTested) {
      AlphaTestContext& ctx = embree.alphaContexts[geomID];
      ctx = {&sm, &data.materials[size_t(sm.mesh.material)].desc, &data.textures};
      rtcSetGeometryUserData(geometry, &ctx);
      rtcSetGeometryIntersectFilterFunction(geometry, alphaTestFilter);
      rtcSetGeometryOccludedFilterFunction(geometry, alphaTestFilter);
    }
    rtcCommitGeometry(geometry);
    rtcAttachGeometryByID(embree.scene, geometry, unsigned(geomID));
    rtcReleaseGeometry(geometry);
  }
  rtcCommitScene(embree.scene);
  if (!embree.firstError.empty()) throw Error(desc.source.string() + ": " + embree.firstError);
  return scene;
}

bool Scene::intersect(const Ray& ray, Hit* hit, bool coherent) const {
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  if (coherent) context.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
  RTCRayHit rh;
  rh.ray.org_x = ray.origin.x;
  rh.ray.org_y = ray.origin.y;
  rh.ray.org_z = ray.origin.z;
  rh.ray.dir_x = ray.direction.x;
  rh.ray.dir_y = ray.direction.y;
  rh.ray.dir_z = ray.direction.z;
  rh.ray.tnear = 0.0f;
  rh.ray.tfar = ray.tMax;
  rh.ray.time = 0.0f;
  rh.ray.mask = ~0u;
  rh.ray.id = 0;
  rh.ray.flags = 0;
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
  rtcIntersect1(embree_->scene, &context, &rh);
  if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return false;
  hit->t = rh.ray.tfar;
  hit->geomID = rh.hit.geomID;
  hit->primID = rh.hit.primID;
  hit->u = rh.hit.u;
  hit->v = rh.hit.v;
  return true;
}

bool Scene::occluded(const Vec3f& origin, const Vec3f& direction, float tMax) const {
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  RTCRay ray;
  ray.org_x = origin.x;
  ray.org_y = origin.y;
  ray.org_z = origin.z;
  ray.dir_x = direction.x;
  ray.dir_y = direction.y;
  ray.dir_z = direction.z;
  ray.tnear = 0.0f;
  ray.tfar = tMax;
  ray.time = 0.0f;
  ray.mask = ~0u;
  ray.id = 0;
  ray.flags = 0;
  rtcOccluded1(embree_->scene, &context, &ray);
  return ray.tfar < 0;  // Embree sets tfar to −∞ on a hit
}

namespace {

template <typename EmbreeRays>
void fillRays(const RayPacket4& rays, EmbreeRays* r) {
  for (int i = 0; i < 4; ++i) {
    r->org_x[i] = rays.ox[i];
    r->org_y[i] = rays.oy[i];
    r->org_z[i] = rays.oz[i];
    r->dir_x[i] = rays.dx[i];
    r->dir_y[i] = rays.dy[i];
    r->dir_z[i] = rays.dz[i];
    r->tnear[i] = 0.0f;
    r->tfar[i] = rays.tMax[i];
    r->time[i] = 0.0f;
    r->mask[i] = ~0u;
    r->id[i] = 0;
    r->flags[i] = 0;
  }
}

}  // namespace

void Scene::intersect4(const int32_t active[4], const RayPacket4& rays, HitPacket4* hits) const {
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  alignas(16) RTCRayHit4 rh;
  fillRays(rays, &rh.ray);
  for (int i = 0; i < 4; ++i) {
    rh.hit.geomID[i] = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0][i] = RTC_INVALID_GEOMETRY_ID;
  }
  rtcIntersect4(active, embree_->scene, &context, &rh);
  for (int i = 0; i < 4; ++i) {
    if (!active[i]) continue;
    hits->geomID[i] =
        rh.hit.geomID[i] == RTC_INVALID_GEOMETRY_ID ? HitPacket4::kNoHit : rh.hit.geomID[i];
    hits->t[i] = rh.ray.tfar[i];
    hits->primID[i] = rh.hit.primID[i];
    hits->u[i] = rh.hit.u[i];
    hits->v[i] = rh.hit.v[i];
  }
}

void Scene::occluded4(const int32_t active[4], const RayPacket4& rays, int32_t blocked[4]) const {
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  alignas(16) RTCRay4 r;
  fillRays(rays, &r);
  rtcOccluded4(active, embree_->scene, &context, &r);
  for (int i = 0; i < 4; ++i) blocked[i] = active[i] && r.tfar[i] < 0 ? -1 : 0;
}

SurfaceInteraction Scene::interaction(const Hit& hit, const Vec3f& rayDirection) const {
  const SceneMesh& sm = data_->meshes[hit.geomID];
  const MeshDesc& mesh = sm.mesh;
  const uint32_t* idx = &mesh.indices[3 * size_t(hit.primID)];
  const float b0 = 1 - hit.u - hit.v, b1 = hit.u, b2 = hit.v;
  const Vec3f p0 = mesh.positions[idx[0]], p1 = mesh.positions[idx[1]], p2 = mesh.positions[idx[2]];

  SurfaceInteraction si;
  si.geomID = hit.geomID;
  si.primID = hit.primID;
  si.material = mesh.material;
  si.position = p0 * b0 + p1 * b1 + p2 * b2;
  si.positionError = barycentricPositionError(p0, p1, p2, b0, b1, b2);
  si.uv = mesh.uvs.empty() ? Vec2f{0, 0}
                           : mesh.uvs[idx[0]] * b0 + mesh.uvs[idx[1]] * b1 + mesh.uvs[idx[2]] * b2;
  if (!sm.flatFrames.empty() && sm.flatFrames[hit.primID].valid) {
    const SceneMesh::FlatFrame& flat = sm.flatFrames[hit.primID];
    si.shadingNormal = flat.shadingNormal;
    si.tangent = flat.tangent;
    si.geometricNormal = flat.geometricNormal;
    si.frontFace = dot(rayDirection, flat.geometricNormal) < 0;
    return si;
  }
  Vec3f ns;
  const Vec3f ng = orientedGeometricNormal(sm, hit.primID, idx, b0, b1, b2, &ns);

  const MaterialDesc& material = data_->materials[size_t(mesh.material)].desc;
  Vec3f tangent;
  float bitangentSign = 1.0f;
  if (!mesh.tangents.empty()) {
    tangent = mesh.tangents[idx[0]].xyz * b0 + mesh.tangents[idx[1]].xyz * b1 +
              mesh.tangents[idx[2]].xyz * b2;
    bitangentSign = mesh.tangents[idx[0]].w;
  } else if (material.normalTexture >= 0 && !mesh.uvs.empty()) {
    // Per-face tangent along increasing u (no vertex normals to build smooth ones from).
    const Vec2f d1 = mesh.uvs[idx[1]] - mesh.uvs[idx[0]], d2 = mesh.uvs[idx[2]] - mesh.uvs[idx[0]];
    const float det = d1.x * d2.y - d1.y * d2.x;
    if (std::abs(det) > 1e-20f) {
      tangent = ((p1 - p0) * d2.y - (p2 - p0) * d1.y) / det;
      const Vec3f bitangent = ((p2 - p0) * d1.x - (p1 - p0) * d2.x) / det;
      bitangentSign = dot(cross(ns, tangent), bitangent) < 0 ? -1.0f : 1.0f;
    }
  }
  Frame frame = lengthSquared(tangent) > 0 ? Frame::fromZX(ns, tangent) : Frame::fromZ(ns);
  if (material.normalTexture >= 0 && !mesh.uvs.empty()) {
    Frame tangentFrame = frame;
    tangentFrame.y = frame.y * bitangentSign;
    const Vec3f mapped = applyNormalMap(material, data_->textures, si.uv, tangentFrame);
    // Keep the mapped normal on the geometric side; a map bending it over would flip shading.
    if (dot(mapped, ng) > 1e-3f) frame = Frame::fromZX(mapped, frame.x);
  }
  si.shadingNormal = frame.z;
  si.tangent = frame.x;
  si.geometricNormal = ng;
  si.frontFace = dot(rayDirection, ng) < 0;
  return si;
}

MaterialPoint Scene::materialPoint(const SurfaceInteraction& si) const {
  return evaluateMaterial(data_->materials[size_t(si.material)].desc, data_->textures, si.uv);
}

Scene::EmitterPoint Scene::emitterPoint(uint32_t geomID, uint32_t primID, float b1, float b2,
                                        const Vec3f& direction) const {
  const SceneMesh& sm = data_->meshes[geomID];
  const MeshDesc& mesh = sm.mesh;
  const uint32_t* idx = &mesh.indices[3 * size_t(primID)];
  const float b0 = 1 - b1 - b2;
  const Vec3f p0 = mesh.positions[idx[0]], p1 = mesh.positions[idx[1]], p2 = mesh.positions[idx[2]];
  EmitterPoint e;
  e.position = p0 * b0 + p1 * b1 + p2 * b2;
  e.positionError = barycentricPositionError(p0, p1, p2, b0, b1, b2);
  Vec3f ns;
  e.geometricNormal = orientedGeometricNormal(sm, primID, idx, b0, b1, b2, &ns);
  const MaterialDesc& m = data_->materials[size_t(mesh.material)].desc;
  const bool front = dot(direction, e.geometricNormal) < 0;
  if (m.isEmissive() && (front || m.doubleSided)) {
    const Vec2f uv = mesh.uvs.empty() || m.emissiveTexture < 0
                         ? Vec2f{0, 0}
                         : mesh.uvs[idx[0]] * b0 + mesh.uvs[idx[1]] * b1 + mesh.uvs[idx[2]] * b2;
    e.Le = evaluateEmission(m, data_->textures, uv);
  }
  return e;
}

Rgb Scene::emitted(const SurfaceInteraction& si) const {
  const MaterialDesc& m = data_->materials[size_t(si.material)].desc;
  if (!m.isEmissive() || !(si.frontFace || m.doubleSided)) return Rgb(0.0f);
  return evaluateEmission(m, data_->textures, si.uv);
}

}  // namespace chorus::render
