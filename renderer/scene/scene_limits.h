#pragma once
// Limits on what a scene file may ask for. glTF files come from anywhere, so every count, size
// and coordinate they hold is checked against these before it is used; each limit is far above
// what a real scene reaches (docs/hardening-inputs.md gives the reasons and the measurements).
#include <cstddef>
#include <cstdint>
#include <sstream>
#include <string>

namespace chorus::render {

// tinygltf 2.7 passes file sizes as unsigned int: a larger file would be read truncated.
inline constexpr uint64_t kMaxGltfFileBytes = 0xFFFFFFFFull;
// Arrays and objects nested deeper than this: parsed JSON is walked recursively (the glTF
// schema itself nests about 8 deep; `extras` are free-form application data).
inline constexpr int kMaxJsonNesting = 128;

// Node hierarchy: depth (cycles end here), node instances visited (a DAG whose levels each list
// the next node twice has 2^depth instances) and (node, primitive) instances, each of which
// becomes one Embree geometry.
inline constexpr int kMaxNodeDepth = 256;
inline constexpr size_t kMaxNodeInstances = size_t(1) << 20;
inline constexpr size_t kMaxPrimitiveInstances = size_t(1) << 20;

// Elements of one accessor, and triangles and vertices of the whole scene with instances
// flattened (chorus stores every instance in world space).
inline constexpr size_t kMaxAccessorElements = size_t(1) << 28;
inline constexpr size_t kMaxSceneTriangles = size_t(1) << 28;
inline constexpr size_t kMaxSceneVertices = size_t(1) << 28;

// What a triangle and a vertex cost in memory from the file to the rendered image (loader
// arrays, runtime scene, Embree BVH; measured, docs/hardening-inputs.md). A scene within the
// limits above may still need more memory than the machine has, and the kernel would kill the
// process rather than fail an allocation: the loader refuses such a scene first.
inline constexpr double kBytesPerTriangle = 176;
inline constexpr double kBytesPerVertex = 32;

// |coordinate| of every vertex, camera and punctual light after the node transforms. Embree
// asserts that ray origins and directions stay below 1.844e18; the farthest origin chorus makes
// from a scene within this bound is the framing camera's, at most √3 · 1e12 / sin(fov / 2)
// ≈ 2.7e17 away for image aspects down to 1/65536.
inline constexpr float kMaxCoordinate = 1e12f;
// Camera aspect ratios (perspective aspectRatio, orthographic xmag / ymag): beyond these the
// image size chosen from one side overflows rather than frames anything.
inline constexpr float kMinCameraAspect = 1.0f / 32.0f;
inline constexpr float kMaxCameraAspect = 32.0f;
// Light colours and intensities, emissive strength, the environment's intensity and its texels:
// radiance-like values above this overflow float once multiplied through a path (the brightest
// texel of a real HDR panorama, the unclipped sun, is about 1e5).
inline constexpr float kMaxRadiance = 1e9f;

// A number for messages about these limits: 4 significant digits ("1e+12", "0.03125", "nan").
inline std::string shortNumber(double v) {
  std::ostringstream text;
  text.precision(4);
  text << v;
  return text.str();
}

}  // namespace chorus::render
