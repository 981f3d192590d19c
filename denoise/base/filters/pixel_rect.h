#pragma once
// A half-open rectangle of pixels [x0, x1) × [y0, y1), the unit the filters work on (tiles,
// clipped windows, the pixels p whose neighbour p + δ lies inside the image).
#include <algorithm>

namespace chorus {

struct PixelRect {
  int x0 = 0, y0 = 0, x1 = 0, y1 = 0;

  static PixelRect image(int width, int height) { return {0, 0, width, height}; }

  int width() const { return std::max(0, x1 - x0); }
  int height() const { return std::max(0, y1 - y0); }
  long long area() const { return (long long)width() * height(); }
  bool empty() const { return x1 <= x0 || y1 <= y0; }
  bool contains(int x, int y) const { return x >= x0 && x < x1 && y >= y0 && y < y1; }

  PixelRect grown(int r) const { return {x0 - r, y0 - r, x1 + r, y1 + r}; }
  PixelRect shifted(int dx, int dy) const { return {x0 + dx, y0 + dy, x1 + dx, y1 + dy}; }
  PixelRect intersect(const PixelRect& o) const {
    return {std::max(x0, o.x0), std::max(y0, o.y0), std::min(x1, o.x1), std::min(y1, o.y1)};
  }
  bool operator==(const PixelRect&) const = default;
};

// The pixels p of a width × height image whose neighbour p + (dx, dy) is inside it too.
inline PixelRect neighbourInside(int width, int height, int dx, int dy) {
  return {std::max(0, -dx), std::max(0, -dy), std::min(width, width - dx),
          std::min(height, height - dy)};
}

}  // namespace chorus
