#include "renderer/scene/radiance_hdr.h"

#include <cctype>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "common/error.h"
#include "common/image/image_limits.h"
#include "common/regular_file.h"

namespace chorus::render {
namespace {

// A worst-case run-length file is a little over 4 bytes per pixel.
constexpr uint64_t kMaxFileBytes = 8 * uint64_t(kMaxImagePixels);

// Scanlines of these widths are run-length encoded by writers (Radiance's own limits).
constexpr int kMinRunLengthWidth = 8, kMaxRunLengthWidth = 32767;

// A cursor over the file's bytes that never reads past the end.
class Bytes {
 public:
  Bytes(const std::vector<unsigned char>& bytes, const std::filesystem::path& path)
      : bytes_(bytes), path_(path) {}

  size_t left() const { return bytes_.size() - pos_; }
  const unsigned char* take(size_t n) {
    if (n > left()) throw fileError(path_, "is truncated (the pixel data ends early)");
    const unsigned char* p = bytes_.data() + pos_;
    pos_ += n;
    return p;
  }
  unsigned char next() { return *take(1); }
  // The next header line without its '\n'; the header must end before the file does.
  std::string line() {
    std::string text;
    for (;;) {
      if (left() == 0) throw fileError(path_, "is not a Radiance HDR file (header never ends)");
      const char c = char(bytes_[pos_++]);
      if (c == '\n') return text;
      text += c;
    }
  }

 private:
  const std::vector<unsigned char>& bytes_;
  const std::filesystem::path& path_;
  size_t pos_ = 0;
};

// stb_image's conversion: mantissas scaled by 2^(exponent − 136), black for exponent 0.
void rgbeToFloat(const unsigned char* rgbe, float* out) {
  if (rgbe[3] == 0) {
    out[0] = out[1] = out[2] = 0.0f;
    return;
  }
  const float scale = std::ldexp(1.0f, int(rgbe[3]) - 136);
  for (int c = 0; c < 3; ++c) out[c] = float(rgbe[c]) * scale;
}

// "-Y H +X W" → (W, H); other orientations are not supported.
bool parseResolution(const std::string& text, int64_t* width, int64_t* height) {
  const auto number = [&](size_t* pos, int64_t* value) {
    const size_t begin = *pos;
    *value = 0;
    while (*pos < text.size() && std::isdigit(static_cast<unsigned char>(text[*pos])) &&
           *pos - begin < 12)
      *value = *value * 10 + (text[(*pos)++] - '0');
    return *pos > begin;
  };
  if (text.rfind("-Y ", 0) != 0) return false;
  size_t pos = 3;
  if (!number(&pos, height)) return false;
  while (pos < text.size() && text[pos] == ' ') ++pos;
  if (text.compare(pos, 3, "+X ") != 0) return false;
  pos += 3;
  return number(&pos, width) && pos == text.size();
}

void readFlat(Bytes& in, Image& image, size_t firstPixel) {
  float* out = image.data();
  for (size_t i = firstPixel; i < image.pixelCount(); ++i) rgbeToFloat(in.take(4), out + 3 * i);
}

// One new-style scanline after its 4-byte marker: each of the four components as runs
// (count > 128: count − 128 copies of one byte) and literals (count ≤ 128 bytes).
void readRunLengthRow(Bytes& in, const std::filesystem::path& path, int width,
                      std::vector<unsigned char>& rgbe, float* out) {
  for (int component = 0; component < 4; ++component) {
    int x = 0;
    while (x < width) {
      int count = in.next();
      const bool run = count > 128;
      if (run) count -= 128;
      if (count == 0 || count > width - x)
        throw fileError(path, "has a corrupt run-length scanline");
      if (run) {
        const unsigned char value = in.next();
        for (int k = 0; k < count; ++k) rgbe[size_t(4 * (x + k) + component)] = value;
      } else {
        const unsigned char* values = in.take(size_t(count));
        for (int k = 0; k < count; ++k) rgbe[size_t(4 * (x + k) + component)] = values[k];
      }
      x += count;
    }
  }
  for (int x = 0; x < width; ++x) rgbeToFloat(&rgbe[size_t(4 * x)], out + 3 * x);
}

}  // namespace

Image readRadianceHdr(const std::filesystem::path& path) {
  const std::vector<unsigned char> bytes = readRegularFile(path, kMaxFileBytes);
  Bytes in(bytes, path);
  if (bytes.size() < 2 || bytes[0] != '#' || bytes[1] != '?')
    throw fileError(path, "is not a Radiance HDR file (no #? signature)");
  in.line();
  bool rgbe = false;
  for (std::string line = in.line(); !line.empty(); line = in.line())
    if (line.rfind("FORMAT=", 0) == 0) {
      if (line != "FORMAT=32-bit_rle_rgbe")
        throw fileError(path, "has " + line + "; chorus reads FORMAT=32-bit_rle_rgbe");
      rgbe = true;
    }
  if (!rgbe) throw fileError(path, "has no FORMAT=32-bit_rle_rgbe line");
  const std::string resolution = in.line();
  int64_t width = 0, height = 0;
  if (!parseResolution(resolution, &width, &height))
    throw fileError(path, "has resolution line '" + resolution.substr(0, 40) +
                              "'; chorus reads '-Y height +X width' images");
  const std::string problem = imageSizeProblem(width, height, 3);
  if (!problem.empty()) throw fileError(path, problem);

  // Before allocating: a few bytes must not claim a gigapixel. A flat row takes 4 bytes per
  // pixel, a run-length row at least its marker and one 2-byte run per 127 pixels and component.
  const bool flat = width < kMinRunLengthWidth || width > kMaxRunLengthWidth;
  const int64_t minRowBytes = flat ? 4 * width : 4 + 4 * 2 * ((width + 126) / 127);
  if (uint64_t(minRowBytes * height) > in.left())
    throw fileError(path, "is truncated (" + std::to_string(width) + "x" + std::to_string(height) +
                              " pixels cannot fit in the rest of the file)");

  Image image(int(width), int(height), 3);
  if (flat) {
    readFlat(in, image, 0);
    return image;
  }
  std::vector<unsigned char> rgbeRow(size_t(4 * width));
  for (int y = 0; y < int(height); ++y) {
    const unsigned char* marker = in.take(4);
    const bool runLength = marker[0] == 2 && marker[1] == 2 && (marker[2] & 0x80) == 0;
    if (!runLength) {
      // A flat file of run-length width: the marker was its first pixel.
      if (y > 0) throw fileError(path, "mixes flat and run-length scanlines");
      rgbeToFloat(marker, image.data());
      readFlat(in, image, 1);
      return image;
    }
    if ((int(marker[2]) << 8 | int(marker[3])) != width)
      throw fileError(path, "has a scanline whose length is not the image width");
    readRunLengthRow(in, path, int(width), rgbeRow, image.pixel(0, y));
  }
  return image;
}

}  // namespace chorus::render
