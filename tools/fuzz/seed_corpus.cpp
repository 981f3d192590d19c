#include "tools/fuzz/seed_corpus.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cstring>
#include <fstream>
#include <sstream>

#include "common/atomic_file.h"
#include "common/error.h"
#include "common/image/exr_io.h"
#include "common/image/png_io.h"
#include "denoise/buffers/buffers_exr.h"
#include "denoise/buffers/sample_buffers.h"
#include "tools/fuzz/fuzz_random.h"
#include "tools/fuzz/glb.h"
#include "tools/fuzz/radiance_hdr.h"
#include "tools/fuzz/sandbox.h"

namespace chorus::fuzz {
namespace fs = std::filesystem;
using nlohmann::json;

namespace {

std::string base64(const std::string& bytes) {
  static const char* digits = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  for (size_t i = 0; i < bytes.size(); i += 3) {
    const size_t n = std::min<size_t>(3, bytes.size() - i);
    uint32_t v = 0;
    for (size_t k = 0; k < 3; ++k) v = (v << 8) | (k < n ? uint8_t(bytes[i + k]) : 0u);
    for (size_t k = 0; k < 4; ++k) out.push_back(k <= n ? digits[(v >> (18 - 6 * k)) & 63] : '=');
  }
  return out;
}

// Binary data for one glTF buffer, each piece its own 4-byte aligned buffer view.
class BufferData {
 public:
  template <typename T>
  int add(const std::vector<T>& values, json& doc, int byteStride = 0) {
    while (bytes_.size() % 4) bytes_.push_back('\0');
    json view = {
        {"buffer", 0}, {"byteOffset", bytes_.size()}, {"byteLength", values.size() * sizeof(T)}};
    if (byteStride) view["byteStride"] = byteStride;
    bytes_.append(reinterpret_cast<const char*>(values.data()), values.size() * sizeof(T));
    doc["bufferViews"].push_back(view);
    return int(doc["bufferViews"].size()) - 1;
  }
  const std::string& bytes() const { return bytes_; }

 private:
  std::string bytes_;
};

int addAccessor(json& doc, int view, int componentType, size_t count, const std::string& type,
                json extra = json::object()) {
  json accessor = {
      {"bufferView", view}, {"componentType", componentType}, {"count", count}, {"type", type}};
  accessor.update(extra);
  doc["accessors"].push_back(accessor);
  return int(doc["accessors"].size()) - 1;
}

json newDocument() {
  return {{"asset", {{"version", "2.0"}, {"generator", "chorus fuzz seed"}}},
          {"scene", 0},
          {"scenes", {{{"nodes", json::array()}}}}};
}

void addRoot(json& doc, json node) {
  doc["nodes"].push_back(std::move(node));
  doc["scenes"][0]["nodes"].push_back(doc["nodes"].size() - 1);
}

// One triangle in a data-URI buffer, a perspective camera and a point light.
std::string triangleGltf() {
  json doc = newDocument();
  BufferData data;
  const int positions =
      addAccessor(doc, data.add(std::vector<float>{-1, 0, 0, 1, 0, 0, 0, 1.5f, 0}, doc), 5126, 3,
                  "VEC3", {{"min", {-1, 0, 0}}, {"max", {1, 1.5, 0}}});
  const int indices =
      addAccessor(doc, data.add(std::vector<uint16_t>{0, 1, 2}, doc), 5123, 3, "SCALAR");
  doc["materials"].push_back(
      {{"pbrMetallicRoughness", {{"baseColorFactor", {0.8, 0.5, 0.3, 1}}, {"metallicFactor", 0}}}});
  const json primitive = {
      {"attributes", {{"POSITION", positions}}}, {"indices", indices}, {"material", 0}};
  doc["meshes"].push_back({{"primitives", json::array({primitive})}});
  doc["cameras"].push_back(
      {{"type", "perspective"}, {"perspective", {{"yfov", 0.9}, {"znear", 0.01}}}});
  addRoot(doc, {{"camera", 0}, {"translation", {0, 0.7, 3}}});
  addRoot(doc, {{"mesh", 0}});
  doc["extensionsUsed"] = {"KHR_lights_punctual"};
  doc["extensions"]["KHR_lights_punctual"]["lights"] = {{{"type", "point"}, {"intensity", 5}}};
  addRoot(doc,
          {{"extensions", {{"KHR_lights_punctual", {{"light", 0}}}}}, {"translation", {0, 1, 1}}});
  doc["buffers"] = {{{"byteLength", data.bytes().size()},
                     {"uri", "data:application/octet-stream;base64," + base64(data.bytes())}}};
  return doc.dump(1);
}

// Quantized (normalized unsigned short) positions with a sparse override, a triangle strip with
// unsigned byte indices, UVs, a 2×2 data-URI PNG base colour texture, an emissive material and
// an orthographic camera.
std::string featuresGltf() {
  json doc = newDocument();
  BufferData data;
  // Four vertices, 8 bytes apart (xyz + padding): a stride the loader must honour.
  const std::vector<uint16_t> quantized = {0, 0,     0, 0, 65535, 0,     0, 0,
                                           0, 65535, 0, 0, 65535, 65535, 0, 0};
  const int positions = addAccessor(doc, data.add(quantized, doc, 8), 5123, 4, "VEC3",
                                    {{"normalized", true}, {"min", {0, 0, 0}}, {"max", {1, 1, 0}}});
  const int sparseIndices = data.add(std::vector<uint8_t>{3, 0, 0, 0}, doc);
  const int sparseValues = data.add(std::vector<uint16_t>{65535, 65535, 30000, 0}, doc);
  doc["accessors"][size_t(positions)]["sparse"] = {
      {"count", 1},
      {"indices", {{"bufferView", sparseIndices}, {"componentType", 5121}}},
      {"values", {{"bufferView", sparseValues}}}};
  const int uvs =
      addAccessor(doc, data.add(std::vector<float>{0, 0, 1, 0, 0, 1, 1, 1}, doc), 5126, 4, "VEC2");
  const int strip =
      addAccessor(doc, data.add(std::vector<uint8_t>{0, 1, 2, 3}, doc), 5121, 4, "SCALAR");
  Image texels(2, 2, 4, 1.0f);
  texels(1, 0, 0) = 0.1f;
  texels(0, 1, 2) = 0.2f;
  const std::vector<uint8_t> png = encodePng(texels);
  doc["images"] = {
      {{"uri", "data:image/png;base64," + base64(std::string(png.begin(), png.end()))}}};
  doc["samplers"] = {{{"magFilter", 9728}, {"wrapS", 33648}, {"wrapT", 33071}}};
  doc["textures"] = {{{"source", 0}, {"sampler", 0}}};
  doc["materials"] = {
      {{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 0}}}, {"roughnessFactor", 0.4}}},
       {"emissiveFactor", {0.5, 0.4, 0.3}},
       {"doubleSided", true}}};
  const json primitive = {{"attributes", {{"POSITION", positions}, {"TEXCOORD_0", uvs}}},
                          {"indices", strip},
                          {"material", 0},
                          {"mode", 5}};
  doc["meshes"].push_back({{"primitives", json::array({primitive})}});
  doc["cameras"].push_back(
      {{"type", "orthographic"},
       {"orthographic", {{"xmag", 1}, {"ymag", 1}, {"znear", 0.01}, {"zfar", 10}}}});
  addRoot(doc, {{"camera", 0}, {"translation", {0.5, 0.5, 2}}});
  addRoot(doc, {{"mesh", 0}, {"scale", {1, 1, 1}}, {"children", {2}}});
  doc["nodes"].push_back(
      {{"mesh", 0}, {"matrix", {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, -1, 1}}});
  doc["buffers"] = {{{"byteLength", data.bytes().size()},
                     {"uri", "data:application/octet-stream;base64," + base64(data.bytes())}}};
  return doc.dump(1);
}

// The Cornell box as .glb: its JSON with the buffer moved into the BIN chunk.
std::string cornellGlb(const fs::path& scenes) {
  json doc = json::parse(readFileBytes(scenes / "cornell-box.gltf"));
  doc["buffers"][0].erase("uri");
  return packGlb({doc.dump(), readFileBytes(scenes / "cornell-box.bin")});
}

Image smoothImage(int width, int height, int channels, uint64_t seed) {
  FuzzRandom rng(seed);
  Image image(width, height, channels);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x)
      for (int c = 0; c < channels; ++c)
        image(x, y, c) = float(x + 1) / float(width) * float(1 + c) + float(rng.below(100)) * 0.01f;
  return image;
}

void writeTungstenDirectory(const fs::path& dir) {
  fs::create_directories(dir);
  uint64_t seed = 1;
  for (const Quantity q : kAllQuantities) {
    const std::string name(quantityName(q));
    for (const char* suffix : {"", "A", "B", "Variance"})
      writeExr(dir / (name + suffix + ".exr"), smoothImage(4, 4, channelCount(q), seed++),
               ExrPixelType::Half);
  }
  writeTextAtomically(dir / "meta.json", "{\"spp\": 8}\n");
}

void writeRenderExr(const fs::path& path) {
  std::vector<SubBuffer> subs;
  uint64_t seed = 100;
  for (int k = 0; k < 2; ++k) {
    SubBuffer sub = SubBuffer::zeros(6, 5);
    for (const Quantity q : kAllQuantities) {
      sub.get(q).mean = smoothImage(6, 5, channelCount(q), seed++);
      sub.get(q).varianceOfMean = smoothImage(6, 5, channelCount(q), seed++);
    }
    sub.sampleCount.fill(4);
    subs.push_back(std::move(sub));
  }
  SampleBuffers buffers(std::move(subs));
  buffers.setEmission(smoothImage(6, 5, 3, seed));  // what separated renders add to every image
  writeExr(path, sampleBuffersToLayers(buffers));
}

// Everything that is not a copy of the project's scenes.
void writeBuiltSeeds(const fs::path& sourceDir, const fs::path& dir) {
  fs::create_directories(dir / "gltf");
  writeTextAtomically(dir / "gltf" / "triangle.gltf", triangleGltf());
  writeTextAtomically(dir / "gltf" / "features.gltf", featuresGltf());
  writeTextAtomically(dir / "gltf" / "cornell-box.glb", cornellGlb(sourceDir / "scenes"));

  fs::create_directories(dir / "exr");
  writeExr(dir / "exr" / "rgb.exr", smoothImage(8, 6, 3, 7));
  writeExr(dir / "exr" / "half-rgba.exr", smoothImage(5, 7, 4, 8), ExrPixelType::Half);
  writeExr(dir / "exr" / "y.exr", smoothImage(3, 9, 1, 9));
  writeRenderExr(dir / "exr" / "render.exr");
  writeTungstenDirectory(dir / "exr" / "tungsten");

  fs::create_directories(dir / "environment");
  writeTextAtomically(dir / "environment" / "flat.hdr",
                      radianceHdr(smoothImage(4, 3, 3, 10), false));
  writeTextAtomically(dir / "environment" / "rle.hdr",
                      radianceHdr(smoothImage(32, 8, 3, 11), true));
  Image runs(64, 4, 3, 0.5f);  // long runs, so that run packets appear
  runs(10, 1, 0) = 4.0f;
  writeTextAtomically(dir / "environment" / "runs-rle.hdr", radianceHdr(runs, true));
  writeExr(dir / "environment" / "sky.exr", smoothImage(16, 8, 3, 12), ExrPixelType::Half);
}

SeedInput singleFile(const fs::path& file) {
  return {file.filename().string(), {{file.filename().string(), readFileBytes(file)}}};
}

}  // namespace

SeedCorpus buildSeedCorpus(const fs::path& sourceDir, const fs::path& dir) {
  fs::remove_all(dir);
  fs::create_directories(dir);
  const Outcome built = runInChild(
      [&] {
        writeBuiltSeeds(sourceDir, dir);
        return std::string();
      },
      ChildLimits{60, 0}, dir / "build.log");
  if (built.verdict != Verdict::Ok)
    throw Error("fuzz: cannot build the seed inputs: " + built.summary);

  SeedCorpus corpus;
  // The project's scenes with every file beside them (buffers, textures).
  const fs::path scenes = sourceDir / "scenes";
  std::vector<CaseFile> beside;
  for (const auto& entry : fs::directory_iterator(scenes)) {
    const std::string ext = entry.path().extension().string();
    if (ext == ".bin" || ext == ".png")
      beside.push_back({entry.path().filename().string(), readFileBytes(entry.path())});
  }
  std::vector<fs::path> gltfs;
  for (const auto& entry : fs::directory_iterator(scenes))
    if (entry.path().extension() == ".gltf") gltfs.push_back(entry.path());
  std::sort(gltfs.begin(), gltfs.end());
  std::sort(beside.begin(), beside.end(),
            [](const CaseFile& a, const CaseFile& b) { return a.name < b.name; });
  for (const fs::path& gltf : gltfs) {
    SeedInput seed = singleFile(gltf);
    seed.files.insert(seed.files.end(), beside.begin(), beside.end());
    corpus.gltf.push_back(std::move(seed));
  }
  for (const char* name : {"triangle.gltf", "features.gltf", "cornell-box.glb"})
    corpus.gltf.push_back(singleFile(dir / "gltf" / name));
  for (const char* name : {"rgb.exr", "half-rgba.exr", "y.exr", "render.exr"})
    corpus.exr.push_back(singleFile(dir / "exr" / name));
  SeedInput tungsten{"tungsten", {}, true};
  std::vector<fs::path> files;
  for (const auto& entry : fs::directory_iterator(dir / "exr" / "tungsten"))
    files.push_back(entry.path());
  std::sort(files.begin(), files.end());
  for (const fs::path& file : files)
    tungsten.files.push_back({file.filename().string(), readFileBytes(file)});
  corpus.exr.push_back(std::move(tungsten));
  for (const char* name : {"flat.hdr", "rle.hdr", "runs-rle.hdr", "sky.exr"})
    corpus.environment.push_back(singleFile(dir / "environment" / name));
  return corpus;
}

}  // namespace chorus::fuzz
