#pragma once
// Display transforms for 8-bit previews: exposure, a tonemapper, then the sRGB transfer curve.
#include <cstdint>
#include <string>

namespace chorus {

enum class Tonemapper {
  Clamp,     // v → min(v, 1)
  Reinhard,  // v → v / (1 + v), per channel
  AcesFit,   // Narkowicz 2015 fit of the ACES filmic curve: v(2.51v+0.03) / (v(2.43v+0.59)+0.14)
};

struct DisplayOptions {
  float exposureStops = 0.0f;  // linear values are multiplied by 2^exposureStops first
  Tonemapper tonemapper = Tonemapper::Clamp;
};

// Parses "clamp", "reinhard" or "aces"; throws chorus::Error otherwise.
Tonemapper parseTonemapper(const std::string& name);

// Linear value → tonemapped value in [0, 1] (NaN and negatives map to 0).
float tonemap(float linear, const DisplayOptions& options);
// Linear [0, 1] → sRGB-encoded [0, 1] (IEC 61966-2-1 piecewise curve).
float linearToSrgb(float linear);
// The whole chain, rounded to the nearest 8-bit code.
uint8_t toDisplayByte(float linear, const DisplayOptions& options);

}  // namespace chorus
