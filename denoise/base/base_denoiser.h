#pragma once
// The interface every base denoiser implements. Configuration is fixed at construction (from a
// ParamMap); run() only executes, is deterministic for any thread count, never writes NaN/Inf,
// and may be called concurrently on different inputs.
#include <string>

#include "common/image/image.h"
#include "denoise/buffers/sample_buffers.h"

namespace chorus {

struct DenoiserRequirements {
  bool features = false;     // reads albedo / normal / depth / visibility
  bool halves = false;       // needs DenoiseInput::halves (two independent halves of its input)
  bool readsHalves = false;  // uses DenoiseInput::halves when present (without needing them)
};

class BaseDenoiser {
 public:
  virtual ~BaseDenoiser() = default;
  virtual std::string name() const = 0;
  virtual DenoiserRequirements requirements() const = 0;
  // Denoises input.whole.color; returns an RGB image of the same size.
  virtual Image run(const DenoiseInput& input) const = 0;
};

}  // namespace chorus
