#include "tools/fuzz/radiance_hdr.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <vector>

namespace chorus::fuzz {
namespace {

std::array<uint8_t, 4> rgbe(float r, float g, float b) {
  const float v = std::max({r, g, b});
  if (!(v >= 1e-32f)) return {0, 0, 0, 0};
  int e = 0;
  const float scale = std::frexp(v, &e) * 256.0f / v;
  return {uint8_t(r * scale), uint8_t(g * scale), uint8_t(b * scale), uint8_t(e + 128)};
}

// One channel of one scanline as runs (128 + n, value) and literals (n, n values).
void encodeRuns(const std::vector<uint8_t>& values, std::string& out) {
  size_t i = 0;
  while (i < values.size()) {
    size_t run = 1;
    while (i + run < values.size() && run < 127 && values[i + run] == values[i]) ++run;
    if (run >= 3) {
      out.push_back(char(128 + run));
      out.push_back(char(values[i]));
      i += run;
      continue;
    }
    size_t literal = 0;
    while (i + literal < values.size() && literal < 128) {
      const size_t j = i + literal;
      if (j + 2 < values.size() && values[j] == values[j + 1] && values[j] == values[j + 2]) break;
      ++literal;
    }
    out.push_back(char(literal));
    for (size_t k = 0; k < literal; ++k) out.push_back(char(values[i + k]));
    i += literal;
  }
}

// Offset of the first pixel byte (after the resolution line), or npos.
size_t dataStart(const std::string& data) {
  const size_t blank = data.find("\n\n");
  if (blank == std::string::npos) return std::string::npos;
  const size_t end = data.find('\n', blank + 2);
  return end == std::string::npos ? std::string::npos : end + 1;
}

}  // namespace

std::string radianceHdr(const Image& rgb, bool rle) {
  const int w = rgb.width(), h = rgb.height();
  std::string out = "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y " + std::to_string(h) + " +X " +
                    std::to_string(w) + "\n";
  for (int y = 0; y < h; ++y) {
    std::vector<std::array<uint8_t, 4>> row;
    for (int x = 0; x < w; ++x) row.push_back(rgbe(rgb(x, y, 0), rgb(x, y, 1), rgb(x, y, 2)));
    if (!rle) {
      for (const auto& p : row) out.append(reinterpret_cast<const char*>(p.data()), 4);
      continue;
    }
    out += {char(2), char(2), char(w >> 8), char(w & 0xFF)};
    for (int c = 0; c < 4; ++c) {
      std::vector<uint8_t> channel;
      for (const auto& p : row) channel.push_back(p[size_t(c)]);
      encodeRuns(channel, out);
    }
  }
  return out;
}

std::string mutateRadianceHdr(std::string& data, FuzzRandom& rng) {
  const size_t start = dataStart(data);
  const size_t resolution =
      start == std::string::npos ? std::string::npos : data.rfind('\n', start - 2);
  switch (rng.below(6)) {
    case 0:
      if (resolution != std::string::npos) {
        static const std::vector<std::string> lines = {"-Y 2147483647 +X 2147483647",
                                                       "-Y 0 +X 0",
                                                       "-Y -5 +X 8",
                                                       "-Y 65536 +X 65536",
                                                       "+Y 8 +X 32",
                                                       "-Y 8 -X 32",
                                                       "-Y 8 +X 99999999999",
                                                       "-Y 1 +X 32768",
                                                       "-Y 1 +X 7",
                                                       "-Y 8 +X 32 extra",
                                                       "-Y 100000 +X 100000",
                                                       "-Y 3 +X 16",
                                                       "-Y 99 +X 32",
                                                       "garbage"};
        const std::string& line = rng.pick(lines);
        data.replace(resolution + 1, start - resolution - 2, line);
        return "resolution line '" + line + "'";
      }
      [[fallthrough]];
    case 1: {
      static const std::vector<std::string> formats = {
          "FORMAT=32-bit_rle_xyze", "FORMAT=", "EXPOSURE=0", std::string(70000, 'F')};
      const size_t line = data.find("FORMAT=");
      const std::string& replacement = rng.pick(formats);
      if (line == std::string::npos) return "no FORMAT line";
      data.replace(line, data.find('\n', line) - line, replacement);
      return "FORMAT line '" + replacement.substr(0, 30) + "'";
    }
    case 2:
    case 3:
      if (start != std::string::npos && start < data.size()) {
        const size_t keep = start + rng.below(data.size() - start);
        data.resize(keep);
        return "truncate inside the pixel data at " + std::to_string(keep) + " (starts at " +
               std::to_string(start) + ")";
      }
      [[fallthrough]];
    case 4:
      if (start != std::string::npos && start < data.size()) {
        const size_t at = start + rng.below(data.size() - start);
        const uint8_t value = rng.pick(std::vector<uint8_t>{0, 1, 127, 128, 129, 255});
        data[at] = char(value);
        return "pixel byte " + std::to_string(at) + " = " + std::to_string(value);
      }
      [[fallthrough]];
    default:
      if (start != std::string::npos && start + 4 <= data.size()) {
        const uint16_t width = rng.pick(std::vector<uint16_t>{0, 1, 7, 8, 255, 0x7FFF, 0xFFFF});
        data[start + 2] = char(width >> 8);
        data[start + 3] = char(width & 0xFF);
        return "first scanline header width " + std::to_string(width);
      }
      return "nothing to edit";
  }
}

}  // namespace chorus::fuzz
