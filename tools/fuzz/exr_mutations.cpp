#include "tools/fuzz/exr_mutations.h"

#include <cstdint>
#include <cstring>
#include <vector>

#include "tools/fuzz/byte_mutations.h"

namespace chorus::fuzz {
namespace {

struct Field {
  size_t offset;
  size_t width;  // bytes, little-endian
  std::string name;
};

int32_t readI32(const std::string& d, size_t at) {
  int32_t v;
  std::memcpy(&v, d.data() + at, 4);
  return v;
}

uint64_t readU64(const std::string& d, size_t at) {
  uint64_t v;
  std::memcpy(&v, d.data() + at, 8);
  return v;
}

// Scanlines per chunk of each compression (OpenEXR's table).
int linesPerChunk(int compression) {
  switch (compression) {
    case 3:  // ZIP
    case 5:  // PXR24
      return 16;
    case 4:  // PIZ
    case 6:  // B44
    case 7:  // B44A
    case 8:  // DWAA
      return 32;
    case 9:  // DWAB
      return 256;
    default:
      return 1;
  }
}

// Every integer field of the header, the offset table and the chunk headers.
std::vector<Field> fieldsOf(const std::string& d) {
  std::vector<Field> fields;
  if (d.size() < 8 || readI32(d, 0) != 20000630) return fields;
  fields.push_back({4, 4, "version and flags"});
  size_t at = 8;
  int yMin = 0, yMax = -1, compression = 0;
  while (at < d.size() && d[at] != '\0') {
    const size_t nameEnd = d.find('\0', at);
    if (nameEnd == std::string::npos) return fields;
    const size_t typeEnd = d.find('\0', nameEnd + 1);
    if (typeEnd == std::string::npos || typeEnd + 5 > d.size()) return fields;
    const std::string name = d.substr(at, nameEnd - at);
    const std::string type = d.substr(nameEnd + 1, typeEnd - nameEnd - 1);
    const size_t sizeAt = typeEnd + 1, valueAt = sizeAt + 4;
    const int32_t size = readI32(d, sizeAt);
    if (size < 0 || valueAt + size_t(size) > d.size()) return fields;
    fields.push_back({sizeAt, 4, name + " size"});
    if (type == "box2i" && size == 16) {
      static const char* corners[4] = {"xMin", "yMin", "xMax", "yMax"};
      for (int i = 0; i < 4; ++i)
        fields.push_back({valueAt + 4 * size_t(i), 4, name + "." + corners[i]});
      if (name == "dataWindow") yMin = readI32(d, valueAt + 4), yMax = readI32(d, valueAt + 12);
    } else if (type == "chlist") {
      size_t c = valueAt;
      while (c < valueAt + size_t(size) && d[c] != '\0') {
        const size_t end = d.find('\0', c);
        if (end == std::string::npos || end + 17 > valueAt + size_t(size)) break;
        const std::string channel = d.substr(c, end - c);
        fields.push_back({end + 1, 4, "channel " + channel + " pixel type"});
        fields.push_back({end + 9, 4, "channel " + channel + " xSampling"});
        fields.push_back({end + 13, 4, "channel " + channel + " ySampling"});
        c = end + 17;
      }
    } else if (type == "compression" || type == "lineOrder") {
      fields.push_back({valueAt, 1, name});
      if (type == "compression" && size >= 1) compression = uint8_t(d[valueAt]);
    }
    at = valueAt + size_t(size);
  }
  const size_t tableAt = at + 1;
  const int64_t chunks = yMax >= yMin ? (int64_t(yMax) - yMin) / linesPerChunk(compression) + 1 : 0;
  for (int64_t i = 0; i < chunks && tableAt + 8 * size_t(i + 1) <= d.size(); ++i) {
    fields.push_back({tableAt + 8 * size_t(i), 8, "offset table entry " + std::to_string(i)});
    const uint64_t chunk = readU64(d, tableAt + 8 * size_t(i));
    if (chunk <= d.size() && d.size() - chunk >= 8) {
      fields.push_back({size_t(chunk), 4, "chunk " + std::to_string(i) + " line"});
      fields.push_back({size_t(chunk) + 4, 4, "chunk " + std::to_string(i) + " data size"});
    }
  }
  return fields;
}

}  // namespace

std::string mutateExrFields(std::string& data, FuzzRandom& rng) {
  const std::vector<Field> fields = fieldsOf(data);
  if (fields.empty()) return mutateBytes(data, rng);
  const Field& field = rng.pick(fields);
  static const std::vector<int64_t> values = {
      0,        -1,      1,       2,         3,         255,           65535,   65536,
      100000,   1 << 20, 1 << 30, INT32_MAX, INT32_MIN, INT32_MAX - 1, -100000, int64_t(1) << 40,
      INT64_MAX};
  int64_t value = rng.pick(values);
  if (rng.chance(0.3) && field.offset + 4 <= data.size())
    value = int64_t(readI32(data, field.offset)) + rng.between(-3, 3);
  for (size_t i = 0; i < field.width; ++i)
    data[field.offset + i] = char((uint64_t(value) >> (8 * i)) & 0xFF);
  return field.name + " = " + std::to_string(field.width == 1 ? int64_t(uint8_t(value)) : value);
}

}  // namespace chorus::fuzz
