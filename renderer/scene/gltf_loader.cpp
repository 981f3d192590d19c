#include "renderer/scene/gltf_loader.h"

#include <tiny_gltf.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <new>
#include <set>

#include "common/error.h"
#include "common/memory_budget.h"
#include "renderer/math/transform.h"
#include "renderer/scene/gltf_accessors.h"
#include "renderer/scene/gltf_file.h"
#include "renderer/scene/gltf_materials.h"
#include "renderer/scene/mesh_tangents.h"
#include "renderer/scene/scene_limits.h"

namespace chorus::render {
namespace {

const std::set<std::string>& supportedExtensions() {
  static const std::set<std::string> names = {"KHR_materials_emissive_strength",
                                              "KHR_materials_transmission",
                                              "KHR_materials_ior",
                                              "KHR_materials_volume",
                                              "KHR_materials_specular",
                                              "KHR_lights_punctual",
                                              "KHR_mesh_quantization"};
  return names;
}

// Extensions that carry no rendering information: ignored without a warning.
bool isMetadataExtension(const std::string& name) {
  return name == "KHR_xmp" || name == "KHR_xmp_json_ld" || name == "KHR_materials_variants";
}

Vec3f vec3At(const std::vector<float>& v, size_t i) {
  return {v[3 * i], v[3 * i + 1], v[3 * i + 2]};
}

// Coordinates beyond kMaxCoordinate (or not finite) are an error; `what` ends in "at".
void checkPosition(Vec3f p, const std::string& what) {
  const auto inRange = [](float x) { return std::abs(x) <= kMaxCoordinate; };  // NaN: false
  if (!(inRange(p.x) && inRange(p.y) && inRange(p.z)))
    throw Error(what + " (" + shortNumber(p.x) + ", " + shortNumber(p.y) + ", " + shortNumber(p.z) +
                "), outside the supported range of ±" + shortNumber(kMaxCoordinate));
}

// A radiance scale from the file: finite and at most kMaxRadiance.
void checkRadiance(double v, const std::string& what) {
  if (!(std::abs(v) <= double(kMaxRadiance)))
    throw Error(what + " is " + shortNumber(v) + ", outside the supported range of ±" +
                shortNumber(kMaxRadiance));
}

// Adds `amount` to a count bounded by `limit`; `what` names the count for the error message.
void addToBudget(size_t* used, size_t amount, size_t limit, const std::string& what) {
  if (amount > limit - *used)
    throw Error("has more than " + std::to_string(limit) + " " + what +
                ", the most chorus supports");
  *used += amount;
}

// Throws chorus::Error (common/memory_budget.h) when the scene's geometry cannot fit in the
// memory the machine has available.
void checkMemory(size_t triangles, size_t vertices, uint64_t availableBytes) {
  const double needed = double(triangles) * kBytesPerTriangle + double(vertices) * kBytesPerVertex;
  checkMemoryBudget(uint64_t(needed),
                    "loading " + std::to_string(triangles) + " triangles and " +
                        std::to_string(vertices) + " vertices (instances included)",
                    availableBytes);
}

// Triangles a primitive of `indexCount` indices makes in `mode`.
size_t trianglesOf(size_t indexCount, int mode) {
  if (mode == TINYGLTF_MODE_TRIANGLES) return indexCount / 3;
  return indexCount >= 2 ? indexCount - 2 : 0;
}

// Triangle list indices for a primitive's topology (glTF 2.0 §3.7.2.1).
std::vector<uint32_t> triangleList(const std::vector<uint32_t>& in, int mode) {
  std::vector<uint32_t> out;
  if (mode == TINYGLTF_MODE_TRIANGLE_STRIP) {
    for (size_t i = 0; i + 2 < in.size(); ++i) {
      const bool odd = i % 2 == 1;
      out.insert(out.end(), {in[i], in[i + (odd ? 2 : 1)], in[i + (odd ? 1 : 2)]});
    }
  } else if (mode == TINYGLTF_MODE_TRIANGLE_FAN) {
    for (size_t i = 1; i + 1 < in.size(); ++i) out.insert(out.end(), {in[i], in[i + 1], in[0]});
  } else {
    out.assign(in.begin(), in.begin() + ptrdiff_t(in.size() - in.size() % 3));
  }
  return out;
}

class SceneBuilder {
 public:
  SceneBuilder(const tinygltf::Model& model, SceneDesc& out)
      : model_(model), out_(out), materials_(model, out) {}

  void build() {
    std::vector<int> roots;
    if (!model_.scenes.empty()) {
      const int scene = model_.defaultScene >= 0 ? model_.defaultScene : 0;
      if (size_t(scene) >= model_.scenes.size())
        throw Error("default scene " + std::to_string(scene) + " does not exist");
      roots = model_.scenes[size_t(scene)].nodes;
    } else {
      // No scenes: every node that is nobody's child is a root.
      std::vector<bool> isChild(model_.nodes.size(), false);
      for (const tinygltf::Node& n : model_.nodes)
        for (int c : n.children)
          if (c >= 0 && size_t(c) < isChild.size()) isChild[size_t(c)] = true;
      for (size_t i = 0; i < model_.nodes.size(); ++i)
        if (!isChild[i]) roots.push_back(int(i));
    }
    for (int root : roots) visit(root, Transform(), 0);
    materials_.decodeImages();
    if (skippedPrimitives_ > 0)
      out_.warnings.push_back("skipped " + std::to_string(skippedPrimitives_) +
                              " point/line primitive(s): chorus renders triangles only");
    for (const MeshDesc& mesh : out_.meshes)
      for (const Vec3f& p : mesh.positions) out_.bounds.extend(p);
  }

 private:
  void visit(int nodeIndex, const Transform& parent, int depth) {
    if (nodeIndex < 0 || size_t(nodeIndex) >= model_.nodes.size())
      throw Error("refers to missing node " + std::to_string(nodeIndex));
    if (depth > kMaxNodeDepth)
      throw Error("node hierarchy is cyclic or deeper than " + std::to_string(kMaxNodeDepth));
    addToBudget(&nodeInstances_, 1, kMaxNodeInstances,
                "node instances (a node counts once per path from the root)");
    const tinygltf::Node& node = model_.nodes[size_t(nodeIndex)];
    const Transform worldFromNode = parent * localTransform(node);
    const std::string label =
        node.name.empty() ? "node " + std::to_string(nodeIndex) : "node '" + node.name + "'";

    if (node.mesh >= 0) {
      if (size_t(node.mesh) >= model_.meshes.size())
        throw Error(label + " refers to missing mesh " + std::to_string(node.mesh));
      const tinygltf::Mesh& mesh = model_.meshes[size_t(node.mesh)];
      for (size_t p = 0; p < mesh.primitives.size(); ++p)
        addPrimitive(
            mesh.primitives[p],
            label + " mesh " + std::to_string(node.mesh) + " primitive " + std::to_string(p),
            worldFromNode);
    }
    if (node.camera >= 0) addCamera(node, label, worldFromNode);
    const auto light = node.extensions.find("KHR_lights_punctual");
    if (light != node.extensions.end() && light->second.Has("light"))
      addLight(light->second.Get("light").GetNumberAsInt(), label, worldFromNode);
    for (int child : node.children) visit(child, worldFromNode, depth + 1);
  }

  static Transform localTransform(const tinygltf::Node& node) {
    if (node.matrix.size() == 16) return Transform::fromColumnMajor(node.matrix.data());
    std::array<double, 3> t{0, 0, 0}, s{1, 1, 1};
    std::array<double, 4> r{0, 0, 0, 1};
    if (node.translation.size() == 3) std::copy_n(node.translation.begin(), 3, t.begin());
    if (node.rotation.size() == 4) std::copy_n(node.rotation.begin(), 4, r.begin());
    if (node.scale.size() == 3) std::copy_n(node.scale.begin(), 3, s.begin());
    return Transform::fromTrs(t, r, s);
  }

  void addPrimitive(const tinygltf::Primitive& prim, const std::string& label,
                    const Transform& worldFromObject) {
    const int mode = prim.mode < 0 ? TINYGLTF_MODE_TRIANGLES : prim.mode;
    if (mode != TINYGLTF_MODE_TRIANGLES && mode != TINYGLTF_MODE_TRIANGLE_STRIP &&
        mode != TINYGLTF_MODE_TRIANGLE_FAN) {
      ++skippedPrimitives_;
      return;
    }
    const auto attribute = [&](const char* name) {
      const auto it = prim.attributes.find(name);
      return it == prim.attributes.end() ? -1 : it->second;
    };
    const int positionAccessor = attribute("POSITION");
    if (positionAccessor < 0) throw Error(label + " has no POSITION");

    addToBudget(&primitiveInstances_, 1, kMaxPrimitiveInstances, "mesh primitive instances");
    // The budgets are charged from the accessor counts before any data is read or allocated.
    const size_t vertexCount = gltf::accessorCount(model_, positionAccessor, label + " POSITION");
    addToBudget(&vertices_, vertexCount, kMaxSceneVertices, "vertices over all instances");
    const size_t indexCount = prim.indices >= 0
                                  ? gltf::accessorCount(model_, prim.indices, label + " indices")
                                  : vertexCount;
    addToBudget(&triangles_, trianglesOf(indexCount, mode), kMaxSceneTriangles,
                "triangles over all instances");
    checkMemory(triangles_, vertices_, availableBytes_);

    MeshDesc mesh;
    mesh.name = label;
    const std::vector<float> positions =
        gltf::readFloats(model_, positionAccessor, 3, label + " POSITION");
    mesh.positions.resize(vertexCount);
    for (size_t i = 0; i < vertexCount; ++i) {
      mesh.positions[i] = worldFromObject.point(vec3At(positions, i));
      checkPosition(mesh.positions[i], label + " has a vertex at");
    }

    std::vector<uint32_t> indices;
    if (prim.indices >= 0) {
      indices = gltf::readIndices(model_, prim.indices, vertexCount);
    } else {
      indices.resize(vertexCount);
      for (size_t i = 0; i < vertexCount; ++i) indices[i] = uint32_t(i);
    }
    mesh.indices = triangleList(indices, mode);
    if (mesh.indices.empty()) return;
    // A mirroring transform turns counter-clockwise front faces clockwise (glTF 2.0 §3.7.4).
    const bool mirrored = worldFromObject.determinant() < 0;
    if (mirrored)
      for (size_t t = 0; t < mesh.indices.size(); t += 3)
        std::swap(mesh.indices[t + 1], mesh.indices[t + 2]);

    if (const int a = attribute("NORMAL"); a >= 0) {
      const std::vector<float> normals = readVertexAttribute(a, 3, vertexCount, label + " NORMAL");
      mesh.normals.resize(vertexCount);
      for (size_t i = 0; i < vertexCount; ++i) {
        const Vec3f n = worldFromObject.normal(vec3At(normals, i));
        const float len = length(n);
        // A degenerate normal is kept as zero; the renderer then uses the geometric normal.
        mesh.normals[i] = len > 0 && std::isfinite(len) ? n / len : Vec3f{};
      }
    }
    if (const int a = attribute("TEXCOORD_0"); a >= 0) {
      const std::vector<float> uvs = readVertexAttribute(a, 2, vertexCount, label + " TEXCOORD_0");
      mesh.uvs.resize(vertexCount);
      for (size_t i = 0; i < vertexCount; ++i) mesh.uvs[i] = {uvs[2 * i], uvs[2 * i + 1]};
    }
    mesh.material = materials_.materialIndex(prim.material);
    const MaterialDesc& material = out_.materials[size_t(mesh.material)];

    if (material.normalTexture >= 0 && !mesh.normals.empty() && !mesh.uvs.empty()) {
      if (const int a = attribute("TANGENT"); a >= 0) {
        const std::vector<float> t = readVertexAttribute(a, 4, vertexCount, label + " TANGENT");
        mesh.tangents.resize(vertexCount);
        for (size_t i = 0; i < vertexCount; ++i) {
          const Vec3f xyz = worldFromObject.vector({t[4 * i], t[4 * i + 1], t[4 * i + 2]});
          const float len = length(xyz);
          mesh.tangents[i] = {len > 0 && std::isfinite(len) ? xyz / len : Vec3f{},
                              (t[4 * i + 3] < 0) != mirrored ? -1.0f : 1.0f};
        }
      } else {
        computeVertexTangents(mesh);
      }
    }
    out_.meshes.push_back(std::move(mesh));
  }

  std::vector<float> readVertexAttribute(int accessor, int components, size_t vertexCount,
                                         const std::string& what) {
    const size_t count = gltf::accessorCount(model_, accessor, what);
    if (count != vertexCount)
      throw Error(what + " has " + std::to_string(count) + " elements but POSITION has " +
                  std::to_string(vertexCount));
    return gltf::readFloats(model_, accessor, components, what);
  }

  void addCamera(const tinygltf::Node& node, const std::string& label,
                 const Transform& worldFromCamera) {
    if (size_t(node.camera) >= model_.cameras.size())
      throw Error(label + " refers to missing camera " + std::to_string(node.camera));
    const tinygltf::Camera& gc = model_.cameras[size_t(node.camera)];
    CameraDesc c;
    c.name = gc.name.empty() ? label : "'" + gc.name + "'";
    double aspect = 0;  // 0: none given
    if (gc.type == "orthographic") {
      c.projection = ProjectionType::Orthographic;
      const double xmag = std::abs(gc.orthographic.xmag), ymag = std::abs(gc.orthographic.ymag);
      for (const double mag : {xmag, ymag})
        if (!(mag > 0 && mag <= double(kMaxCoordinate)))
          throw Error("camera " + c.name + " has xmag " + shortNumber(xmag) + " and ymag " +
                      shortNumber(ymag) + "; each must lie in (0, " + shortNumber(kMaxCoordinate) +
                      "]");
      c.xmag = float(xmag);
      c.ymag = float(ymag);
      aspect = xmag / ymag;
    } else {
      c.yfov = float(gc.perspective.yfov);
      if (!(c.yfov > 0 && c.yfov < kPi)) throw Error("camera " + c.name + " has an invalid yfov");
      if (gc.perspective.aspectRatio > 0) aspect = gc.perspective.aspectRatio;
    }
    if (aspect != 0 && !(aspect >= kMinCameraAspect && aspect <= kMaxCameraAspect))
      throw Error("camera " + c.name + " has aspect ratio " + shortNumber(aspect) +
                  ", outside the supported " + shortNumber(kMinCameraAspect) + " … " +
                  shortNumber(kMaxCameraAspect));
    c.aspectRatio = float(aspect);
    // Orthonormal frame; scale in the node transform only moves the camera, it does not zoom.
    c.position = worldFromCamera.point({0, 0, 0});
    c.forward = normalize(worldFromCamera.vector({0, 0, -1}));
    const Vec3f up = worldFromCamera.vector({0, 1, 0});
    c.right = normalize(cross(c.forward, up));
    c.up = cross(c.right, c.forward);
    if (!isFinite(c.forward) || !isFinite(c.right))
      throw Error(label + " has a degenerate camera transform");
    checkPosition(c.position, "camera " + c.name + " is at");
    out_.cameras.push_back(c);
  }

  void addLight(int index, const std::string& label, const Transform& worldFromLight) {
    if (index < 0 || size_t(index) >= model_.lights.size())
      throw Error(label + " refers to missing KHR_lights_punctual light " + std::to_string(index));
    const tinygltf::Light& gl = model_.lights[size_t(index)];
    PunctualLightDesc l;
    l.name = gl.name.empty() ? label : "'" + gl.name + "'";
    if (gl.type == "spot") {
      l.type = PunctualLightType::Spot;
    } else if (gl.type == "directional") {
      l.type = PunctualLightType::Directional;
    } else if (gl.type != "point") {
      throw Error("light " + l.name + " has unknown type '" + gl.type + "'");
    }
    if (gl.color.size() >= 3) {
      for (int i = 0; i < 3; ++i) checkRadiance(gl.color[size_t(i)], "light " + l.name + " color");
      l.color = Rgb{float(std::max(0.0, gl.color[0])), float(std::max(0.0, gl.color[1])),
                    float(std::max(0.0, gl.color[2]))};
    }
    checkRadiance(gl.intensity, "light " + l.name + " intensity");
    l.intensity = float(std::max(0.0, gl.intensity));
    l.position = worldFromLight.point({0, 0, 0});
    l.direction = normalize(worldFromLight.vector({0, 0, -1}));
    l.outerConeAngle = float(std::clamp(gl.spot.outerConeAngle, 1e-4, double(kPi) / 2));
    l.innerConeAngle = float(std::clamp(gl.spot.innerConeAngle, 0.0, double(l.outerConeAngle)));
    if (!isFinite(l.position) || !isFinite(l.direction))
      throw Error(label + " has a degenerate light transform");
    checkPosition(l.position, "light " + l.name + " is at");
    out_.lights.push_back(l);
  }

  const tinygltf::Model& model_;
  SceneDesc& out_;
  gltf::MaterialReader materials_;
  int skippedPrimitives_ = 0;
  size_t nodeInstances_ = 0, primitiveInstances_ = 0, triangles_ = 0, vertices_ = 0;
  const uint64_t availableBytes_ = availableMemoryBytes();  // read once per scene
};

void checkExtensions(const tinygltf::Model& model, SceneDesc& out) {
  for (const std::string& name : model.extensionsRequired)
    if (!isSupportedGltfExtension(name))
      throw Error("requires extension " + name + ", which chorus does not support");
  std::set<std::string> used(model.extensionsUsed.begin(), model.extensionsUsed.end());
  for (const tinygltf::Material& m : model.materials)
    for (const auto& [name, value] : m.extensions) used.insert(name);
  for (const std::string& name : used) {
    if (isSupportedGltfExtension(name) || isMetadataExtension(name)) continue;
    out.ignoredExtensions.push_back(name);
    out.warnings.push_back("ignoring unsupported extension " + name);
  }
}

}  // namespace

bool isSupportedGltfExtension(const std::string& name) {
  return supportedExtensions().count(name) > 0;
}

SceneDesc loadGltf(const std::filesystem::path& path) {
  SceneDesc out;
  out.source = path;
  try {
    tinygltf::Model model;
    gltf::readModel(path, &model);  // its errors name the file
    try {
      checkExtensions(model, out);
      SceneBuilder(model, out).build();
    } catch (const Error& e) {
      throw fileError(path, e.what());
    }
  } catch (const std::bad_alloc&) {
    // Within the limits of scene_limits.h a scene can still outgrow this machine's memory.
    throw fileError(path, "needs more memory than is available");
  }
  if (out.meshes.empty()) throw fileError(path, "contains no triangles to render");
  return out;
}

}  // namespace chorus::render
