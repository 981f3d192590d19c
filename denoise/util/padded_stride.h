#pragma once
// Tile planes one cache line apart. A tile's area is usually a multiple of 4 KiB (256 × 16,
// 256 × 32 floats): planes that far apart map to the same L1 sets and alias in the store
// buffer, and the NL-means accumulations touch many of them per pixel. One cache line more per
// plane spreads them over the sets (RDFC −3…−11 % in A/B runs).
#include <cstddef>

namespace chorus {

inline size_t paddedPlaneStride(size_t area) {
  return area + 16;
}

}  // namespace chorus
