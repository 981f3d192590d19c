#include "denoise/image/png_io.h"

#include <stb_image_write.h>

#include <algorithm>
#include <cmath>
#include <fstream>

#include "denoise/util/atomic_file.h"
#include "denoise/util/error.h"

namespace chorus {

std::vector<uint8_t> encodePng(const Image& image, const DisplayOptions& options) {
  const int channels = image.channels();
  if (channels != 1 && channels != 3 && channels != 4)
    throw Error("PNG needs 1, 3 or 4 channels, not " + std::to_string(channels));
  if (image.empty()) throw Error("cannot encode an empty image as PNG");

  std::vector<uint8_t> bytes(image.size());
  for (size_t i = 0; i < image.size(); ++i) {
    const float v = image.data()[i];
    const bool alpha = channels == 4 && i % 4 == 3;
    bytes[i] = alpha
                   ? uint8_t(std::lround(255.0f * std::clamp(std::isnan(v) ? 0.0f : v, 0.0f, 1.0f)))
                   : toDisplayByte(v, options);
  }
  std::vector<uint8_t> encoded;
  auto append = [](void* context, void* data, int size) {
    auto* out = static_cast<std::vector<uint8_t>*>(context);
    out->insert(out->end(), static_cast<uint8_t*>(data), static_cast<uint8_t*>(data) + size);
  };
  if (!stbi_write_png_to_func(append, &encoded, image.width(), image.height(), channels,
                              bytes.data(), image.width() * channels))
    throw Error("PNG encoding failed");
  return encoded;
}

void writePng(const std::filesystem::path& path, const Image& image,
              const DisplayOptions& options) {
  std::vector<uint8_t> encoded;
  try {
    encoded = encodePng(image, options);
  } catch (const Error& e) {
    throw fileError(path, e.what());
  }
  writeAtomically(path, [&](const std::filesystem::path& tmp) {
    std::ofstream out(tmp, std::ios::binary);
    out.write(reinterpret_cast<const char*>(encoded.data()), std::streamsize(encoded.size()));
    out.close();
    if (!out) throw fileError(path, "cannot write");
  });
}

}  // namespace chorus
