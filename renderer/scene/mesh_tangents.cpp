#include "renderer/scene/mesh_tangents.h"

#include <cmath>

namespace chorus::render {

void computeVertexTangents(MeshDesc& mesh) {
  const size_t n = mesh.positions.size();
  std::vector<Vec3f> tangentSum(n), bitangentSum(n);
  for (size_t t = 0; t + 2 < mesh.indices.size(); t += 3) {
    const uint32_t i0 = mesh.indices[t], i1 = mesh.indices[t + 1], i2 = mesh.indices[t + 2];
    const Vec3f e1 = mesh.positions[i1] - mesh.positions[i0];
    const Vec3f e2 = mesh.positions[i2] - mesh.positions[i0];
    const Vec2f d1 = mesh.uvs[i1] - mesh.uvs[i0];
    const Vec2f d2 = mesh.uvs[i2] - mesh.uvs[i0];
    // Solve [e1 e2] = [dpdu dpdv] [d1 d2] for the position derivatives along u and v.
    const float det = d1.x * d2.y - d1.y * d2.x;
    if (!(std::abs(det) > 1e-20f)) continue;
    const float inv = 1.0f / det;
    const Vec3f dpdu = (e1 * d2.y - e2 * d1.y) * inv;
    const Vec3f dpdv = (e2 * d1.x - e1 * d2.x) * inv;
    const float lenU = length(dpdu), lenV = length(dpdv);
    if (!(lenU > 0 && lenV > 0) || !std::isfinite(lenU) || !std::isfinite(lenV)) continue;
    // Unit directions weighted by the triangle's area, so large triangles dominate.
    const float area = 0.5f * length(cross(e1, e2));
    const Vec3f tangent = dpdu * (area / lenU), bitangent = dpdv * (area / lenV);
    for (uint32_t i : {i0, i1, i2}) {
      tangentSum[i] += tangent;
      bitangentSum[i] += bitangent;
    }
  }
  mesh.tangents.assign(n, Tangent{});
  for (size_t i = 0; i < n; ++i) {
    const Vec3f normal = mesh.normals[i];
    const Frame fallback = Frame::fromZ(normal);
    Vec3f t = tangentSum[i] - normal * dot(normal, tangentSum[i]);
    const float len = length(t);
    if (!(len > 1e-12f)) {
      mesh.tangents[i] = {fallback.x, 1.0f};
      continue;
    }
    t = t / len;
    const float w = dot(cross(normal, t), bitangentSum[i]) < 0 ? -1.0f : 1.0f;
    mesh.tangents[i] = {t, w};
  }
}

}  // namespace chorus::render
