#pragma once
// Reading a .gltf or .glb file into a tinygltf::Model without trusting it. Internal to the glTF
// loader. tinygltf is handed only what was checked here: the file and every external buffer or
// image it names must be regular files (a FIFO would block open() forever) of at most
// kMaxGltfFileBytes, the JSON must not nest deeper than kMaxJsonNesting (the parsed values are
// walked recursively), and an image stored in a buffer view must lie inside its buffer
// (tinygltf 2.7 hands the image callback byteLength bytes at byteOffset unchecked). Images are
// kept encoded; the material reader decodes the ones it uses.
#include <tiny_gltf.h>

#include <filesystem>
#include <string>

namespace chorus::render::gltf {

// Fills `model`. Throws chorus::Error naming `path` when the file cannot be used; tinygltf's
// warnings are dropped (chorus reports what it ignores itself).
void readModel(const std::filesystem::path& path, tinygltf::Model* model);

}  // namespace chorus::render::gltf
