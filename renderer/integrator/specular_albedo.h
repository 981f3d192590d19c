#pragma once
// Directional albedo of the GGX specular reflection lobe with Schlick Fresnel,
//   E(μ) = ∫ F(wo·h) D(h) G(wo, wi) / (4 μ cos θi) cos θi dωi,   μ = cos θo,
// which is linear in the Fresnel end points: E = f0 · scale + f90 · bias. The layered glTF
// BSDF uses it to hand the diffuse base exactly the energy the specular layer leaves
// (albedo scaling, Kelemen & Szirmay-Kalos 2001; Kulla & Conty 2017).
//
// The terms come from a table over (μ, roughness) integrated numerically ahead of time
// (specular_albedo_integral.h; compiled in from specular_albedo_table.inc), interpolated
// bilinearly. The cosine-weighted average 2 ∫ E(μ) μ dμ is the exact integral of that same
// interpolant, so the albedo scaling conserves energy exactly with respect to the table.
namespace chorus::render {

struct SpecularAlbedoTerms {
  float scale = 0;  // multiplies f0
  float bias = 0;   // multiplies f90
  float albedo(float f0, float f90) const { return f0 * scale + f90 * bias; }
};

// E at cosine `cosTheta` for perceptual roughness `roughness` (both clamped to [0,1]).
// Roughness 0 is the smooth limit E = F(μ).
SpecularAlbedoTerms specularAlbedo(float cosTheta, float roughness);
// The cosine-weighted hemispherical average 2 ∫ E(μ) μ dμ.
SpecularAlbedoTerms specularAlbedoAverage(float roughness);

// The table at one roughness, for repeated lookups at different cosines (a BSDF keeps one).
// Default-constructed it is unusable; construct it with a roughness.
class SpecularAlbedoRow {
 public:
  SpecularAlbedoRow() = default;
  explicit SpecularAlbedoRow(float roughness);
  SpecularAlbedoTerms at(float cosTheta) const;
  SpecularAlbedoTerms average() const { return average_; }

 private:
  const SpecularAlbedoTerms* lower_ = nullptr;  // the two table rows around the roughness
  const SpecularAlbedoTerms* upper_ = nullptr;
  float weight_ = 0;  // of the upper row
  SpecularAlbedoTerms average_;
};

}  // namespace chorus::render
