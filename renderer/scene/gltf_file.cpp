#include "renderer/scene/gltf_file.h"

#include <climits>
#include <cstdint>
#include <cstring>
#include <exception>
#include <string>
#include <vector>

#include "common/error.h"
#include "common/json_nesting.h"
#include "common/regular_file.h"
#include "renderer/scene/scene_limits.h"

namespace chorus::render::gltf {
namespace {

bool hasGlbMagic(const std::vector<unsigned char>& bytes) {
  return bytes.size() >= 4 && std::memcmp(bytes.data(), "glTF", 4) == 0;
}

// The JSON text of the file: all of a .gltf, the first chunk of a .glb (its binary chunk may
// hold any bytes). A malformed GLB header yields what is there; tinygltf then rejects it.
std::span<const unsigned char> jsonText(const std::vector<unsigned char>& bytes) {
  if (!hasGlbMagic(bytes)) return bytes;
  constexpr size_t kHeaderBytes = 20;  // magic, version, length, chunk length, chunk type
  if (bytes.size() < kHeaderBytes) return {};
  uint32_t chunkLength;
  std::memcpy(&chunkLength, bytes.data() + 12, 4);
  const size_t available = bytes.size() - kHeaderBytes;
  return {bytes.data() + kHeaderBytes, std::min(size_t(chunkLength), available)};
}

// tinygltf's file system: existence without opening anything, reads of regular files only.
bool pathExists(const std::string& path, void*) {
  std::error_code ec;
  return std::filesystem::exists(path, ec);
}
std::string pathAsGiven(const std::string& path, void*) {
  return path;
}
// `user` is a std::string that keeps the first refusal ("x.bin: is a directory, not a file")
// for the error message.
bool readCheckedFile(std::vector<unsigned char>* out, std::string* err, const std::string& path,
                     void* user) {
  try {
    *out = readRegularFile(path, kMaxGltfFileBytes);
    return true;
  } catch (const Error& e) {
    auto* firstRefusal = static_cast<std::string*>(user);
    if (firstRefusal->empty()) *firstRefusal = e.what();
    if (err) *err += e.what();
    return false;
  }
}

// tinygltf's image callback: keep the encoded bytes, after checking that an image stored in a
// buffer view lies inside its buffer. `user` is the model being filled, whose buffers and
// buffer views are parsed before its images.
bool keepEncodedImage(tinygltf::Image* image, const int index, std::string* err, std::string*, int,
                      int, const unsigned char* bytes, int size, void* user) {
  if (image->bufferView >= 0) {
    const auto* model = static_cast<const tinygltf::Model*>(user);
    const tinygltf::BufferView& view = model->bufferViews[size_t(image->bufferView)];
    const size_t bufferBytes = model->buffers[size_t(view.buffer)].data.size();
    if (view.byteOffset > bufferBytes || view.byteLength > bufferBytes - view.byteOffset ||
        view.byteLength > size_t(INT_MAX)) {
      if (err)
        *err += "image " + std::to_string(index) + " lies outside buffer " +
                std::to_string(view.buffer);
      return false;
    }
  }
  if (size < 0) return false;
  image->image.assign(bytes, bytes + size);
  image->as_is = true;
  return true;
}

std::string firstLine(const std::string& text) {
  size_t begin = 0;
  while (begin < text.size()) {
    size_t end = text.find('\n', begin);
    if (end == std::string::npos) end = text.size();
    std::string line = text.substr(begin, end - begin);
    while (!line.empty() && (line.back() == '\r' || line.back() == ' ')) line.pop_back();
    if (!line.empty()) return line;
    begin = end + 1;
  }
  return "";
}

}  // namespace

void readModel(const std::filesystem::path& path, tinygltf::Model* model) {
  const std::vector<unsigned char> bytes = readRegularFile(path, kMaxGltfFileBytes);
  if (jsonNestsDeeperThan(jsonText(bytes), kMaxJsonNesting))
    throw fileError(path, "nests JSON arrays or objects more than " +
                              std::to_string(kMaxJsonNesting) + " levels deep");

  tinygltf::TinyGLTF loader;
  std::string firstRefusal;
  loader.SetFsCallbacks({pathExists, pathAsGiven, readCheckedFile, nullptr, &firstRefusal});
  loader.SetImageLoader(keepEncodedImage, model);
  std::string err, warn;
  const std::string baseDir = path.parent_path().string();
  const auto size = static_cast<unsigned int>(bytes.size());
  bool ok = false;
  try {
    ok = hasGlbMagic(bytes)
             ? loader.LoadBinaryFromMemory(model, &err, &warn, bytes.data(), size, baseDir)
             : loader.LoadASCIIFromString(
                   model, &err, &warn, reinterpret_cast<const char*>(bytes.data()), size, baseDir);
  } catch (const Error&) {
    throw;
  } catch (const std::exception& e) {
    // tinygltf itself throws on some malformed files (a .glb whose buffer 0 has byteLength 0:
    // std::out_of_range from its own bounds-checked access).
    throw fileError(path, std::string("not a readable glTF file: the parser stopped (") +
                              firstLine(e.what()) + ")");
  }
  if (!ok) {
    // A refused buffer (images are optional to tinygltf: a refused one only goes missing).
    if (!firstRefusal.empty() && err.find(firstRefusal) != std::string::npos)
      throw fileError(path, "cannot read " + firstRefusal);
    const std::string reason = firstLine(err);
    throw fileError(path, "not a readable glTF file" + (reason.empty() ? "" : ": " + reason));
  }
}

}  // namespace chorus::render::gltf
