#pragma once
// glTF 2.0 (.gltf with external or data-URI buffers, and .glb) → SceneDesc.
//
// Supported: node hierarchies (matrix or TRS), meshes with several primitives, every index and
// attribute component type (KHR_mesh_quantization), sparse accessors, triangle lists, strips
// and fans (points and lines are skipped with one warning), missing normals (flat shading),
// missing tangents (generated when a normal map needs them), pbrMetallicRoughness with
// textures, normal/emissive textures, KHR_materials_emissive_strength, _transmission, _ior,
// _volume, _specular, alphaMode MASK/BLEND, doubleSided, KHR_lights_punctual, perspective and
// orthographic cameras. Other extensions the file uses are ignored with one warning line each;
// an unsupported extension listed in extensionsRequired is an error.
#include <filesystem>

#include "renderer/scene/scene_desc.h"

namespace chorus::render {

// Throws chorus::Error "<path>: <problem>" for a missing, malformed or truncated file, a missing
// buffer or texture image, an unsupported required extension, or anything beyond the limits of
// scene_limits.h (counts, instances, coordinates, camera parameters, radiances, memory).
SceneDesc loadGltf(const std::filesystem::path& path);

// Extensions chorus implements (the rest are ignored with a warning, or rejected when required).
bool isSupportedGltfExtension(const std::string& name);

}  // namespace chorus::render
