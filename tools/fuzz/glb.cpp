#include "tools/fuzz/glb.h"

#include <cstdint>
#include <cstring>

namespace chorus::fuzz {
namespace {

constexpr uint32_t kMagic = 0x46546C67, kJsonChunk = 0x4E4F534A, kBinChunk = 0x004E4942;

void putU32(std::string& out, uint32_t v) {
  for (int i = 0; i < 4; ++i) out.push_back(char((v >> (8 * i)) & 0xFF));
}

uint32_t getU32(const std::string& bytes, size_t at) {
  uint32_t v;
  std::memcpy(&v, bytes.data() + at, 4);
  return v;
}

void putChunk(std::string& out, uint32_t type, std::string data, char pad) {
  while (data.size() % 4) data.push_back(pad);
  putU32(out, uint32_t(data.size()));
  putU32(out, type);
  out += data;
}

}  // namespace

std::string packGlb(const GlbParts& parts) {
  std::string chunks;
  putChunk(chunks, kJsonChunk, parts.json, ' ');
  if (!parts.bin.empty()) putChunk(chunks, kBinChunk, parts.bin, '\0');
  std::string out;
  putU32(out, kMagic);
  putU32(out, 2);
  putU32(out, uint32_t(12 + chunks.size()));
  return out + chunks;
}

std::optional<GlbParts> unpackGlb(const std::string& bytes) {
  if (bytes.size() < 20 || getU32(bytes, 0) != kMagic) return std::nullopt;
  GlbParts parts;
  size_t at = 12;
  for (int chunk = 0; chunk < 2 && at + 8 <= bytes.size(); ++chunk) {
    const size_t length = getU32(bytes, at), type = getU32(bytes, at + 4);
    if (length > bytes.size() - at - 8) return std::nullopt;
    const std::string data = bytes.substr(at + 8, length);
    if (chunk == 0 && type != kJsonChunk) return std::nullopt;
    (chunk == 0 ? parts.json : parts.bin) = data;
    at += 8 + length;
  }
  return parts;
}

}  // namespace chorus::fuzz
