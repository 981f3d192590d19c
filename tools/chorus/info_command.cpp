// chorus info SCENE: what a glTF scene contains, as chorus sees it (no Embree build needed).
#include <cmath>
#include <cstdio>
#include <iostream>
#include <string>

#include "renderer/scene/gltf_loader.h"
#include "tools/chorus/command.h"

namespace chorus::cli {
namespace {

using namespace chorus::render;

std::string materialFeatures(const MaterialDesc& m) {
  std::string f;
  const auto add = [&](const std::string& s) { f += (f.empty() ? "" : ", ") + s; };
  if (m.specular == 0 && m.metallic == 0 && m.transmission == 0) {
    add("lambertian");
  } else if (m.metallic >= 1) {
    add("metal");
  } else if (m.metallic > 0) {
    add("metallic " + std::to_string(m.metallic).substr(0, 4));
  }
  if (m.baseColorTexture >= 0) add("base colour texture");
  if (m.metallicRoughnessTexture >= 0) add("metallic-roughness texture");
  if (m.normalTexture >= 0) add("normal map");
  if (m.isEmissive()) add(m.emissiveTexture >= 0 ? "emissive (textured)" : "emissive");
  if (m.isTransmissive()) add(m.hasVolume ? "transmission + volume" : "thin transmission");
  if (m.specular != 1 || m.specularColor.maxComponent() != 1) add("KHR_materials_specular");
  if (m.alphaMode == AlphaMode::Mask) add("alpha mask");
  if (m.alphaMode == AlphaMode::Blend) add("alpha blend (stochastic)");
  if (m.doubleSided) add("double-sided");
  if (f.empty()) add("dielectric");
  return f;
}

void printVec(const char* label, Vec3f v) {
  std::printf("%s(%.4g, %.4g, %.4g)", label, v.x, v.y, v.z);
}

void runInfo(const std::string& path) {
  const SceneDesc scene = loadGltf(path);
  size_t emissiveTriangles = 0;
  for (const MeshDesc& mesh : scene.meshes)
    if (scene.materials[size_t(mesh.material)].isEmissive())
      emissiveTriangles += mesh.triangleCount();

  std::printf("scene       %s\n", path.c_str());
  std::printf("triangles   %zu in %zu mesh instance(s)\n", scene.triangleCount(),
              scene.meshes.size());
  std::printf("materials   %zu used\n", scene.materials.size());
  for (const MaterialDesc& m : scene.materials)
    std::printf("  %-28s %s\n", m.name.c_str(), materialFeatures(m).c_str());
  size_t texels = 0;
  for (const ImageDesc& image : scene.images) texels += size_t(image.width) * size_t(image.height);
  std::printf("textures    %zu texture(s), %zu image(s) decoded (%.1f MB)\n", scene.textures.size(),
              scene.images.size(), double(texels) * 4.0 / 1e6);

  int points = 0, spots = 0, directionals = 0;
  for (const PunctualLightDesc& l : scene.lights) {
    points += l.type == PunctualLightType::Point;
    spots += l.type == PunctualLightType::Spot;
    directionals += l.type == PunctualLightType::Directional;
  }
  std::printf("lights      %zu emissive triangle(s), %d point, %d spot, %d directional\n",
              emissiveTriangles, points, spots, directionals);
  if (emissiveTriangles == 0 && scene.lights.empty())
    std::printf(
        "            none: renders under a uniform white environment unless --background "
        "or --env is given\n");

  std::printf("cameras     %zu\n", scene.cameras.size());
  for (size_t i = 0; i < scene.cameras.size(); ++i) {
    const CameraDesc& c = scene.cameras[i];
    if (c.projection == ProjectionType::Perspective)
      std::printf("  [%zu] %s perspective, yfov %.1f°", i, c.name.c_str(), c.yfov * 180 / kPi);
    else
      std::printf("  [%zu] %s orthographic, xmag %.4g ymag %.4g", i, c.name.c_str(), c.xmag,
                  c.ymag);
    if (c.aspectRatio > 0) std::printf(", aspect %.4g", c.aspectRatio);
    printVec(", at ", c.position);
    printVec(" looking ", c.forward);
    std::printf("\n");
  }
  if (scene.cameras.empty())
    std::printf("            none: the default camera frames the bounds\n");

  printVec("bounds      min ", scene.bounds.min);
  printVec(" max ", scene.bounds.max);
  printVec(" size ", scene.bounds.diagonal());
  std::printf("\n");
  for (const std::string& w : scene.warnings) std::cerr << "chorus: warning: " << w << "\n";
}

const RegisterCommand registration(20, [](CLI::App& app) {
  auto path = std::make_shared<std::string>();
  CLI::App* cmd = app.add_subcommand(
      "info",
      "Summarise a glTF scene: triangles, materials and their features, lights, cameras, "
      "bounds");
  cmd->add_option("scene", *path, "glTF scene (.gltf or .glb)")->required();
  cmd->callback([path] { runInfo(*path); });
});

}  // namespace
}  // namespace chorus::cli
