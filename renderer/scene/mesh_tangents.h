#pragma once
// Per-vertex tangents for normal mapping when a file has none (glTF spec: "When tangents are not
// specified, client implementations SHOULD calculate tangents using default MikkTSpace
// algorithms"). This is the classic per-vertex accumulation that MikkTSpace refines: each
// triangle's UV-aligned tangent (the direction of increasing u) and bitangent are summed, area
// weighted, at its vertices, then orthogonalised against the vertex normal; the sign w records
// the handedness of the UV mapping.
#include "renderer/scene/scene_desc.h"

namespace chorus::render {

// Fills mesh.tangents (one per vertex). Requires mesh.normals and mesh.uvs. Vertices whose
// triangles have degenerate UVs get an arbitrary tangent perpendicular to the normal.
void computeVertexTangents(MeshDesc& mesh);

}  // namespace chorus::render
