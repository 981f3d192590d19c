#include "renderer/scene/gltf_accessors.h"

#include <algorithm>
#include <cstring>

#include "common/error.h"
#include "renderer/scene/scene_limits.h"

namespace chorus::render::gltf {
namespace {

int componentSize(int componentType) {
  switch (componentType) {
    case TINYGLTF_COMPONENT_TYPE_BYTE:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
      return 1;
    case TINYGLTF_COMPONENT_TYPE_SHORT:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT:
      return 2;
    case TINYGLTF_COMPONENT_TYPE_INT:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT:
    case TINYGLTF_COMPONENT_TYPE_FLOAT:
      return 4;
    default:
      return 0;
  }
}

int componentsOf(int type) {
  switch (type) {
    case TINYGLTF_TYPE_SCALAR:
      return 1;
    case TINYGLTF_TYPE_VEC2:
      return 2;
    case TINYGLTF_TYPE_VEC3:
      return 3;
    case TINYGLTF_TYPE_VEC4:
      return 4;
    default:
      return 0;
  }
}

// One component at `p`, converted to float (glTF 2.0 §3.11, "normalized" integers).
float readComponent(const unsigned char* p, int componentType, bool normalized) {
  switch (componentType) {
    case TINYGLTF_COMPONENT_TYPE_BYTE: {
      const auto v = static_cast<int8_t>(*p);
      return normalized ? std::max(float(v) / 127.0f, -1.0f) : float(v);
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
      return normalized ? float(*p) / 255.0f : float(*p);
    case TINYGLTF_COMPONENT_TYPE_SHORT: {
      int16_t v;
      std::memcpy(&v, p, 2);
      return normalized ? std::max(float(v) / 32767.0f, -1.0f) : float(v);
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
      uint16_t v;
      std::memcpy(&v, p, 2);
      return normalized ? float(v) / 65535.0f : float(v);
    }
    case TINYGLTF_COMPONENT_TYPE_INT: {
      int32_t v;
      std::memcpy(&v, p, 4);
      return float(v);
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: {
      uint32_t v;
      std::memcpy(&v, p, 4);
      return normalized ? float(double(v) / 4294967295.0) : float(v);
    }
    default: {
      float v;
      std::memcpy(&v, p, 4);
      return v;
    }
  }
}

uint32_t readIndexComponent(const unsigned char* p, int componentType) {
  switch (componentType) {
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
      return *p;
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
      uint16_t v;
      std::memcpy(&v, p, 2);
      return v;
    }
    default: {
      uint32_t v;
      std::memcpy(&v, p, 4);
      return v;
    }
  }
}

bool isUnsignedIndexType(int componentType) {
  return componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE ||
         componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT ||
         componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT;
}

// Whether `count` elements of `elementBytes` bytes, `stride` apart from `byteOffset`, fit in
// `length` bytes. Offsets and strides come straight from the file, so no step may wrap.
bool elementsFit(size_t byteOffset, size_t count, size_t stride, size_t elementBytes,
                 size_t length) {
  if (count == 0) return true;
  if (byteOffset > length) return false;
  size_t extent;
  if (__builtin_mul_overflow(stride, count - 1, &extent) ||
      __builtin_add_overflow(extent, elementBytes, &extent))
    return false;
  return extent <= length - byteOffset;
}

void checkCount(size_t count, const std::string& what) {
  if (count > kMaxAccessorElements)
    throw Error(what + " has count " + std::to_string(count) +
                "; chorus reads accessors of at most " + std::to_string(kMaxAccessorElements) +
                " elements");
}

size_t nonNegative(int value, const std::string& what) {
  if (value < 0) throw Error(what + " is negative (" + std::to_string(value) + ")");
  return size_t(value);
}

// A checked view of `count` elements of `elementBytes` bytes, `stride` apart, starting at
// `byteOffset` inside buffer view `viewIndex`.
struct ElementView {
  const unsigned char* first = nullptr;
  size_t stride = 0;
};

ElementView viewElements(const tinygltf::Model& model, int viewIndex, size_t byteOffset,
                         size_t count, size_t elementBytes, size_t strideOverride,
                         const std::string& what) {
  if (viewIndex < 0 || size_t(viewIndex) >= model.bufferViews.size())
    throw Error(what + " refers to missing bufferView " + std::to_string(viewIndex));
  const tinygltf::BufferView& view = model.bufferViews[size_t(viewIndex)];
  if (view.buffer < 0 || size_t(view.buffer) >= model.buffers.size())
    throw Error("bufferView " + std::to_string(viewIndex) + " refers to missing buffer " +
                std::to_string(view.buffer));
  const tinygltf::Buffer& buffer = model.buffers[size_t(view.buffer)];
  if (view.byteOffset > buffer.data.size() ||
      view.byteLength > buffer.data.size() - view.byteOffset)
    throw Error("bufferView " + std::to_string(viewIndex) + " lies outside buffer " +
                std::to_string(view.buffer) + " (" + std::to_string(buffer.data.size()) +
                " bytes; truncated file?)");
  const size_t stride = strideOverride ? strideOverride : elementBytes;
  if (stride < elementBytes ||
      !elementsFit(byteOffset, count, stride, elementBytes, view.byteLength))
    throw Error(what + " reads past the end of bufferView " + std::to_string(viewIndex));
  return {buffer.data.data() + view.byteOffset + (count > 0 ? byteOffset : 0), stride};
}

const tinygltf::Accessor& accessorAt(const tinygltf::Model& model, int index,
                                     const std::string& what) {
  if (index < 0 || size_t(index) >= model.accessors.size())
    throw Error(what + " refers to missing accessor " + std::to_string(index));
  return model.accessors[size_t(index)];
}

size_t viewStride(const tinygltf::Model& model, int viewIndex) {
  return viewIndex >= 0 && size_t(viewIndex) < model.bufferViews.size()
             ? model.bufferViews[size_t(viewIndex)].byteStride
             : 0;
}

}  // namespace

size_t accessorCount(const tinygltf::Model& model, int index, const std::string& what) {
  const size_t count = accessorAt(model, index, what).count;
  checkCount(count, what + " (accessor " + std::to_string(index) + ")");
  return count;
}

std::vector<float> readFloats(const tinygltf::Model& model, int index, int components,
                              const std::string& what) {
  const tinygltf::Accessor& accessor = accessorAt(model, index, what);
  const std::string name = what + " (accessor " + std::to_string(index) + ")";
  checkCount(accessor.count, name);
  const int size = componentSize(accessor.componentType);
  if (size == 0) throw Error(name + " has an invalid componentType");
  if (componentsOf(accessor.type) != components)
    throw Error(name + " has " + std::to_string(componentsOf(accessor.type)) +
                " components, expected " + std::to_string(components));
  const size_t elementBytes = size_t(size) * size_t(components);

  ElementView dense;
  if (accessor.bufferView >= 0)
    dense = viewElements(model, accessor.bufferView, accessor.byteOffset, accessor.count,
                         elementBytes, viewStride(model, accessor.bufferView), name);
  ElementView sparseIndices, sparseValues;
  size_t sparseCount = 0;
  const int indexType = accessor.sparse.indices.componentType;
  if (accessor.sparse.isSparse) {
    sparseCount = nonNegative(accessor.sparse.count, name + " sparse count");
    if (sparseCount > accessor.count)
      throw Error(name + " has more sparse values (" + std::to_string(sparseCount) +
                  ") than elements");
    if (!isUnsignedIndexType(indexType))
      throw Error(name + " has sparse indices of an invalid type");
    sparseIndices = viewElements(
        model, accessor.sparse.indices.bufferView,
        nonNegative(accessor.sparse.indices.byteOffset, name + " sparse indices byteOffset"),
        sparseCount, size_t(componentSize(indexType)), 0, name + " sparse indices");
    sparseValues = viewElements(
        model, accessor.sparse.values.bufferView,
        nonNegative(accessor.sparse.values.byteOffset, name + " sparse values byteOffset"),
        sparseCount, elementBytes, 0, name + " sparse values");
  }

  // Every view is checked: now the count is known to be backed by data (or bounded).
  std::vector<float> out(accessor.count * size_t(components), 0.0f);
  if (dense.first)
    for (size_t i = 0; i < accessor.count; ++i)
      for (int c = 0; c < components; ++c)
        out[i * size_t(components) + size_t(c)] =
            readComponent(dense.first + i * dense.stride + size_t(c) * size_t(size),
                          accessor.componentType, accessor.normalized);
  for (size_t i = 0; i < sparseCount; ++i) {
    const uint32_t target =
        readIndexComponent(sparseIndices.first + i * sparseIndices.stride, indexType);
    if (target >= accessor.count) throw Error(name + " has a sparse index out of range");
    for (int c = 0; c < components; ++c)
      out[size_t(target) * size_t(components) + size_t(c)] =
          readComponent(sparseValues.first + i * sparseValues.stride + size_t(c) * size_t(size),
                        accessor.componentType, accessor.normalized);
  }
  return out;
}

std::vector<uint32_t> readIndices(const tinygltf::Model& model, int index, size_t vertexCount) {
  const tinygltf::Accessor& accessor = accessorAt(model, index, "indices");
  const std::string name = "indices (accessor " + std::to_string(index) + ")";
  checkCount(accessor.count, name);
  const int type = accessor.componentType;
  if (!isUnsignedIndexType(type)) throw Error(name + " must be unsigned byte, short or int");
  if (accessor.type != TINYGLTF_TYPE_SCALAR) throw Error(name + " must be scalar");
  if (accessor.bufferView < 0 || accessor.sparse.isSparse)
    throw Error(name + " must be a plain bufferView accessor");
  const ElementView v =
      viewElements(model, accessor.bufferView, accessor.byteOffset, accessor.count,
                   size_t(componentSize(type)), viewStride(model, accessor.bufferView), name);
  std::vector<uint32_t> out(accessor.count);
  for (size_t i = 0; i < accessor.count; ++i) {
    out[i] = readIndexComponent(v.first + i * v.stride, type);
    if (out[i] >= vertexCount)
      throw Error(name + " holds vertex index " + std::to_string(out[i]) + " but there are " +
                  std::to_string(vertexCount) + " vertices");
  }
  return out;
}

}  // namespace chorus::render::gltf
