#include "renderer/scene/texture.h"

#include <stb_image.h>

#include <climits>
#include <cmath>

#include "common/error.h"

namespace chorus::render {
namespace {

const std::array<float, 256>& srgbTable() {
  static const std::array<float, 256> table = [] {
    std::array<float, 256> t{};
    for (int i = 0; i < 256; ++i) {
      const double c = i / 255.0;
      t[size_t(i)] = float(c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4));
    }
    return t;
  }();
  return table;
}

// Texel coordinate of one axis after the wrap mode.
int wrap(int i, int size, WrapMode mode) {
  if (unsigned(i) < unsigned(size)) return i;  // inside the image: every mode keeps it
  switch (mode) {
    case WrapMode::ClampToEdge:
      return i < 0 ? 0 : (i >= size ? size - 1 : i);
    case WrapMode::MirroredRepeat: {
      const int period = 2 * size;
      int m = i % period;
      if (m < 0) m += period;
      return m < size ? m : period - 1 - m;
    }
    case WrapMode::Repeat:
    default: {
      int m = i % size;
      return m < 0 ? m + size : m;
    }
  }
}

// floor() of a texel coordinate, kept inside int range for huge or non-finite uvs.
int safeFloor(float x) {
  if (!(std::abs(x) < 1e9f)) return 0;
  return int(std::floor(x));
}

}  // namespace

float srgbByteToLinear(uint8_t code) {
  return srgbTable()[code];
}

ImageDesc decodeImage(std::span<const uint8_t> bytes, const std::string& name) {
  if (bytes.empty() || bytes.size() > size_t(INT_MAX)) throw Error("image '" + name + "' is empty");
  int width = 0, height = 0, channels = 0;
  unsigned char* pixels =
      stbi_load_from_memory(bytes.data(), int(bytes.size()), &width, &height, &channels, 4);
  if (!pixels)
    throw Error("cannot decode image '" + name +
                "': " + (stbi_failure_reason() ? stbi_failure_reason() : "unknown format"));
  ImageDesc image;
  image.name = name;
  image.width = width;
  image.height = height;
  image.rgba.assign(pixels, pixels + size_t(width) * size_t(height) * 4);
  stbi_image_free(pixels);

  double sumLinear[4] = {0, 0, 0, 0}, sumSrgb[4] = {0, 0, 0, 0};
  for (size_t i = 0; i < image.rgba.size(); i += 4)
    for (int c = 0; c < 4; ++c) {
      sumLinear[c] += image.rgba[i + size_t(c)] / 255.0;
      sumSrgb[c] += srgbByteToLinear(image.rgba[i + size_t(c)]);
    }
  const double pixelCount = double(width) * double(height);
  for (int c = 0; c < 4; ++c) {
    image.meanLinear[c] = float(sumLinear[c] / pixelCount);
    image.meanSrgbDecoded[c] = float(sumSrgb[c] / pixelCount);
  }
  return image;
}

std::array<float, 4> Texture::texel(int ix, int iy, ColorEncoding encoding) const {
  const uint8_t* p = image_->rgba.data() + (size_t(iy) * size_t(image_->width) + size_t(ix)) * 4;
  if (encoding == ColorEncoding::Srgb)
    return {srgbByteToLinear(p[0]), srgbByteToLinear(p[1]), srgbByteToLinear(p[2]), p[3] / 255.0f};
  return {p[0] / 255.0f, p[1] / 255.0f, p[2] / 255.0f, p[3] / 255.0f};
}

std::array<float, 4> Texture::sample(Vec2f uv, ColorEncoding encoding) const {
  const int w = image_->width, h = image_->height;
  const float x = uv.x * float(w), y = uv.y * float(h);
  if (desc_.nearest)
    return texel(wrap(safeFloor(x), w, desc_.wrapS), wrap(safeFloor(y), h, desc_.wrapT), encoding);
  // Bilinear between the four texel centres around (x, y); each axis is wrapped once.
  const float fx = x - 0.5f, fy = y - 0.5f;
  const int x0 = safeFloor(fx), y0 = safeFloor(fy);
  const float tx = std::abs(fx) < 1e9f ? fx - float(x0) : 0.0f;
  const float ty = std::abs(fy) < 1e9f ? fy - float(y0) : 0.0f;
  const int ix0 = wrap(x0, w, desc_.wrapS), ix1 = wrap(x0 + 1, w, desc_.wrapS);
  const int iy0 = wrap(y0, h, desc_.wrapT), iy1 = wrap(y0 + 1, h, desc_.wrapT);
  const auto a = texel(ix0, iy0, encoding), b = texel(ix1, iy0, encoding);
  const auto c = texel(ix0, iy1, encoding), d = texel(ix1, iy1, encoding);
  std::array<float, 4> out{};
  for (size_t i = 0; i < 4; ++i)
    out[i] = (1 - ty) * ((1 - tx) * a[i] + tx * b[i]) + ty * ((1 - tx) * c[i] + tx * d[i]);
  return out;
}

}  // namespace chorus::render
