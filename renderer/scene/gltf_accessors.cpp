#include "renderer/scene/gltf_accessors.h"

#include <algorithm>
#include <cstring>

#include "common/error.h"

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
  if (count > 0) {
    const size_t last = byteOffset + stride * (count - 1) + elementBytes;
    if (byteOffset > view.byteLength || last > view.byteLength || stride < elementBytes)
      throw Error(what + " reads past the end of bufferView " + std::to_string(viewIndex));
  }
  return {buffer.data.data() + view.byteOffset + byteOffset, stride};
}

const tinygltf::Accessor& accessorAt(const tinygltf::Model& model, int index,
                                     const std::string& what) {
  if (index < 0 || size_t(index) >= model.accessors.size())
    throw Error(what + " refers to missing accessor " + std::to_string(index));
  return model.accessors[size_t(index)];
}

}  // namespace

size_t accessorCount(const tinygltf::Model& model, int index, const std::string& what) {
  return accessorAt(model, index, what).count;
}

std::vector<float> readFloats(const tinygltf::Model& model, int index, int components,
                              const std::string& what) {
  const tinygltf::Accessor& accessor = accessorAt(model, index, what);
  const std::string name = what + " (accessor " + std::to_string(index) + ")";
  const int size = componentSize(accessor.componentType);
  if (size == 0) throw Error(name + " has an invalid componentType");
  if (componentsOf(accessor.type) != components)
    throw Error(name + " has " + std::to_string(componentsOf(accessor.type)) +
                " components, expected " + std::to_string(components));
  const size_t elementBytes = size_t(size) * size_t(components);
  std::vector<float> out(accessor.count * size_t(components), 0.0f);

  if (accessor.bufferView >= 0) {
    const size_t byteStride = model.bufferViews.size() > size_t(accessor.bufferView)
                                  ? model.bufferViews[size_t(accessor.bufferView)].byteStride
                                  : 0;
    const ElementView v = viewElements(model, accessor.bufferView, accessor.byteOffset,
                                       accessor.count, elementBytes, byteStride, name);
    for (size_t i = 0; i < accessor.count; ++i)
      for (int c = 0; c < components; ++c)
        out[i * size_t(components) + size_t(c)] =
            readComponent(v.first + i * v.stride + size_t(c) * size_t(size), accessor.componentType,
                          accessor.normalized);
  }

  if (accessor.sparse.isSparse) {
    const size_t n = size_t(std::max(0, accessor.sparse.count));
    const int indexType = accessor.sparse.indices.componentType;
    const int indexSize = componentSize(indexType);
    if (indexSize == 0 || indexType == TINYGLTF_COMPONENT_TYPE_FLOAT)
      throw Error(name + " has sparse indices of an invalid type");
    const ElementView idx = viewElements(model, accessor.sparse.indices.bufferView,
                                         size_t(std::max(0, accessor.sparse.indices.byteOffset)), n,
                                         size_t(indexSize), 0, name + " sparse indices");
    const ElementView val = viewElements(model, accessor.sparse.values.bufferView,
                                         size_t(std::max(0, accessor.sparse.values.byteOffset)), n,
                                         elementBytes, 0, name + " sparse values");
    for (size_t i = 0; i < n; ++i) {
      const uint32_t target = readIndexComponent(idx.first + i * idx.stride, indexType);
      if (target >= accessor.count) throw Error(name + " has a sparse index out of range");
      for (int c = 0; c < components; ++c)
        out[size_t(target) * size_t(components) + size_t(c)] =
            readComponent(val.first + i * val.stride + size_t(c) * size_t(size),
                          accessor.componentType, accessor.normalized);
    }
  }
  return out;
}

std::vector<uint32_t> readIndices(const tinygltf::Model& model, int index, size_t vertexCount) {
  const tinygltf::Accessor& accessor = accessorAt(model, index, "indices");
  const std::string name = "indices (accessor " + std::to_string(index) + ")";
  const int type = accessor.componentType;
  if (type != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE &&
      type != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT &&
      type != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT)
    throw Error(name + " must be unsigned byte, short or int");
  if (accessor.type != TINYGLTF_TYPE_SCALAR) throw Error(name + " must be scalar");
  if (accessor.bufferView < 0 || accessor.sparse.isSparse)
    throw Error(name + " must be a plain bufferView accessor");
  const size_t size = size_t(componentSize(type));
  const size_t byteStride = size_t(accessor.bufferView) < model.bufferViews.size()
                                ? model.bufferViews[size_t(accessor.bufferView)].byteStride
                                : 0;
  const ElementView v = viewElements(model, accessor.bufferView, accessor.byteOffset,
                                     accessor.count, size, byteStride, name);
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
