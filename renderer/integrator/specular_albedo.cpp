#include "renderer/integrator/specular_albedo.h"

#include <algorithm>
#include <cmath>
#include <iterator>

#include "renderer/integrator/specular_albedo_integral.h"

namespace chorus::render {
namespace {

#include "renderer/integrator/specular_albedo_table.inc"

static_assert(std::size(kDirectional) ==
                      size_t(kSpecularAlbedoRoughnesses) * kSpecularAlbedoCosines &&
                  std::size(kAverage) == size_t(kSpecularAlbedoRoughnesses),
              "specular_albedo_table.inc does not match the grid: regenerate it");

// Index and weight of linear interpolation on [0,1] sampled at `count` points.
void gridPosition(float x, int count, int* i, float* w) {
  const float s = std::clamp(x, 0.0f, 1.0f) * float(count - 1);
  *i = std::min(int(s), count - 2);
  *w = s - float(*i);
}

SpecularAlbedoTerms lerp(SpecularAlbedoTerms a, SpecularAlbedoTerms b, float w) {
  return {a.scale + (b.scale - a.scale) * w, a.bias + (b.bias - a.bias) * w};
}

}  // namespace

SpecularAlbedoRow::SpecularAlbedoRow(float roughness) {
  int j;
  gridPosition(std::sqrt(std::clamp(roughness, 0.0f, 1.0f)), kSpecularAlbedoRoughnesses, &j,
               &weight_);
  lower_ = &kDirectional[size_t(j) * kSpecularAlbedoCosines];
  upper_ = lower_ + kSpecularAlbedoCosines;
  average_ = lerp(kAverage[j], kAverage[j + 1], weight_);
}

SpecularAlbedoTerms SpecularAlbedoRow::at(float cosTheta) const {
  int i;
  float wi;
  gridPosition(std::sqrt(std::clamp(cosTheta, 0.0f, 1.0f)), kSpecularAlbedoCosines, &i, &wi);
  return lerp(lerp(lower_[i], lower_[i + 1], wi), lerp(upper_[i], upper_[i + 1], wi), weight_);
}

SpecularAlbedoTerms specularAlbedo(float cosTheta, float roughness) {
  return SpecularAlbedoRow(roughness).at(cosTheta);
}

SpecularAlbedoTerms specularAlbedoAverage(float roughness) {
  return SpecularAlbedoRow(roughness).average();
}

}  // namespace chorus::render
