#pragma once
// Reading glTF accessors into plain arrays, with every bound checked (a malformed or truncated
// file must fail with a message, never read out of bounds): counts are at most
// kMaxAccessorElements (scene_limits.h), and offsets, strides and counts are checked against
// their buffer view with arithmetic that cannot wrap before anything is allocated or read. Internal
// to the glTF loader. Errors are thrown as chorus::Error without the file name; loadGltf() adds it.
#include <tiny_gltf.h>

#include <cstdint>
#include <string>
#include <vector>

namespace chorus::render::gltf {

// Accessor `index` as `count × components` floats. Integer components are converted as the
// glTF spec says: normalized ones to [0, 1] / [−1, 1], others by value. Sparse accessors are
// applied. Throws when the accessor's type does not have `components` components.
std::vector<float> readFloats(const tinygltf::Model& model, int index, int components,
                              const std::string& what);

// An index accessor (unsigned byte, short or int scalars), checked against `vertexCount`.
std::vector<uint32_t> readIndices(const tinygltf::Model& model, int index, size_t vertexCount);

// The element count of accessor `index` (checked to exist and to be at most
// kMaxAccessorElements), for budgets charged before any data is read.
size_t accessorCount(const tinygltf::Model& model, int index, const std::string& what);

}  // namespace chorus::render::gltf
