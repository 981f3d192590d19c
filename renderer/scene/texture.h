#pragma once
// Texture images: decoding (stb_image: PNG, JPEG, BMP, …) and filtered lookups with the glTF
// sampler's wrap modes. Texels stay 8-bit in memory; colour textures are decoded from sRGB at
// lookup through a table.
#include <array>
#include <cstdint>
#include <span>
#include <string>

#include "renderer/math/vec.h"
#include "renderer/scene/scene_desc.h"

namespace chorus::render {

// Decodes an encoded image (any format stb_image reads) to 8-bit RGBA. Throws chorus::Error
// (without file name) when the bytes are not a readable image.
ImageDesc decodeImage(std::span<const uint8_t> bytes, const std::string& name);

enum class ColorEncoding { Linear, Srgb };

// sRGB-encoded 8-bit code → linear value (IEC 61966-2-1).
float srgbByteToLinear(uint8_t code);

class Texture {
 public:
  Texture() = default;
  Texture(const ImageDesc& image, const TextureDesc& desc) : image_(&image), desc_(desc) {}

  // RGBA at texture coordinate uv (glTF: (0,0) is the top-left corner of the image), filtered
  // bilinearly unless the sampler asks for NEAREST. With Srgb, RGB are decoded to linear;
  // alpha is always linear.
  std::array<float, 4> sample(Vec2f uv, ColorEncoding encoding) const;

  const ImageDesc& image() const { return *image_; }

 private:
  // The texel at wrapped coordinates (inside the image).
  std::array<float, 4> texel(int ix, int iy, ColorEncoding encoding) const;

  const ImageDesc* image_ = nullptr;
  TextureDesc desc_;
};

}  // namespace chorus::render
