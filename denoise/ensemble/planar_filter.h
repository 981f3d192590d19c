#pragma once
// The joint-bilateral filter core shared by the MSE window (mse_estimate.h) and the weight
// filter (weight_filter.h): many planar float images filtered with one kernel
//
//   k(p,q) = exp(− kSpatial·|p−q|² − kNormal·|n(p) − n(q)|² − kAlbedo·|a(p) − a(q)|²
//                − kColor·Σ_c (z_c(p) − z_c(q))² / (V_c(p) + V_c(q) + 1e-6)),
//   out(p) = Σ_q k(p,q) in(q) / Σ_q k(p,q),   |q − p|∞ ≤ radius, q inside the image.
//
// Loops run over offsets and then over contiguous x, so that they vectorise (the exponential
// is fastExpNegated, denoise/util/fast_exp.h). Each output value is one fixed-order sum: results do
// not depend on how rows are split between threads.
#include <span>
#include <vector>

namespace chorus {

struct BilateralKernel {
  int radius = 7;
  int step = 1;  // offsets on a grid of this spacing only (|δ|∞ ≤ radius): a sparse wide window
  float kSpatial = 0;  // 1 / (2σ²) of each term; 0 disables it
  float kNormal = 0;
  float kAlbedo = 0;
  float kColor = 0;  // needs PlanarGuides::color and ::variance
  // Vector width of the accumulation: 16 lanes where the CPU has AVX-512, else 8 (the same bits
  // either way; tests force each).
  enum class Width { ForThisCpu, Sixteen, Eight } width = Width::ForThisCpu;
};

// Guides for the whole image, 3 planes each (plane c at data + c·width·height); finite values,
// the colour guide with |z| ≤ 1e6 and 0 ≤ V ≤ 1e12 (see makeColorGuide).
struct PlanarGuides {
  int width = 0, height = 0;
  std::vector<float> normal, albedo;   // required (zeros when unknown)
  std::vector<float> color, variance;  // optional: the colour term
};

// Filters rows [y0, y1) of every input plane. Input plane j holds rows [inY0, inY0 + rows) with
// row stride `width` and must cover [y0 − radius, y1 + radius) ∩ [0, height). Output plane j
// receives rows [y0, y1) (row y at out[j] + (y − y0)·width).
void filterPlaneRows(const PlanarGuides& guides, const BilateralKernel& kernel,
                     std::span<const float* const> in, int inY0, int y0, int y1,
                     std::span<float* const> out);

}  // namespace chorus
