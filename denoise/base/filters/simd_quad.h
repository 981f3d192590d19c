#pragma once
// Four floats as one GCC vector (an SSE register on x86-64): explicit vector code for the few
// hot loops the auto-vectoriser handles badly. Element-wise + - * / behave as on floats; loads
// and stores are unaligned.
#include <cstring>

namespace chorus {

using Quad = float __attribute__((vector_size(4 * sizeof(float))));

inline Quad loadQuad(const float* p) {
  Quad v;
  std::memcpy(&v, p, sizeof v);
  return v;
}

inline void storeQuad(float* p, Quad v) {
  std::memcpy(p, &v, sizeof v);
}

inline Quad splatQuad(float v) {
  return Quad{v, v, v, v};
}

}  // namespace chorus
