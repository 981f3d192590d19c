#pragma once
// The numerical integration behind the specular-albedo table (specular_albedo.h). The renderer
// reads the table from specular_albedo_table.inc, which tools/generate/specular_albedo_table
// writes with these functions (and a test checks that it still matches them), so that no
// process spends its start-up integrating.
#include <vector>

#include "renderer/integrator/specular_albedo.h"

namespace chorus::render {

// The table's grid. The cosine axis is uniform in x = sqrt(μ): the albedo changes fastest at
// grazing angles, where masking sets in at μ ~ α. The roughness axis is uniform in sqrt(r),
// finer near smooth.
inline constexpr int kSpecularAlbedoCosines = 64;      // μ_i = (i / 63)²
inline constexpr int kSpecularAlbedoRoughnesses = 32;  // r_j = (j / 31)²

// E's terms at one cosine and perceptual roughness, by deterministic quadrature.
SpecularAlbedoTerms integrateSpecularAlbedo(float cosTheta, float roughness);

struct SpecularAlbedoTable {
  // [roughness][cosine] row-major, and per roughness the cosine-weighted average of the
  // bilinear interpolant.
  std::vector<SpecularAlbedoTerms> directional, average;
};
SpecularAlbedoTable integrateSpecularAlbedoTable();

}  // namespace chorus::render
