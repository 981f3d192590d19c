// chorus info SCENE [--methods LIST]: what a glTF scene contains, as chorus sees it (no Embree
// build needed), what of the renderer's machinery it needs, and what a render for the members
// of LIST records and writes and what it leaves out (docs/leave-out.md).
#include <cmath>
#include <cstdio>
#include <iostream>
#include <string>

#include "denoise/pipeline/member_planes.h"
#include "renderer/render.h"
#include "renderer/scene/gltf_loader.h"
#include "tools/chorus/command.h"
#include "tools/chorus/render_denoise.h"

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

std::string joined(const std::vector<std::string>& items) {
  std::string text;
  for (const std::string& item : items) text += (text.empty() ? "" : ", ") + item;
  return text.empty() ? "nothing" : text;
}

// The renderer's optional machinery and whether the scene uses it. Each piece runs only where a
// material or light asks for it (texture lookups per textured slot, the specular layer per
// material that has one, environment sampling only for an emitting environment), so a scene
// without it pays nothing: these lines say which case the scene is in.
void printNeeds(const SceneDesc& scene, size_t emissiveTriangles) {
  size_t textured = 0, layered = 0;
  for (const MaterialDesc& m : scene.materials) {
    textured += m.baseColorTexture >= 0 || m.metallicRoughnessTexture >= 0 ||
                m.normalTexture >= 0 || m.emissiveTexture >= 0 || m.transmissionTexture >= 0 ||
                m.specularTexture >= 0 || m.specularColorTexture >= 0;
    layered += !(m.specular == 0 && m.metallic == 0 && m.transmission == 0);
  }
  std::printf("needs       textures: ");
  if (textured > 0)
    std::printf("%zu material(s) look textures up\n", textured);
  else
    std::printf("none (no texture lookups)\n");
  std::printf("            glossy: ");
  if (layered > 0)
    std::printf("%zu material(s) with a specular layer, metal or transmission\n", layered);
  else
    std::printf("none (every material is Lambertian: no microfacet lobe is evaluated)\n");
  const bool defaultEnvironment = emissiveTriangles == 0 && scene.lights.empty();
  std::printf("            environment: ");
  if (defaultEnvironment)
    std::printf("the uniform default (constant: no importance map) unless --env\n");
  else
    std::printf("none unless --env or --background (no environment sampling)\n");
  // docs/emission.md: seen emission is kept out of the members and pooled with extra rays.
  std::printf("            seen emission: ");
  if (emissiveTriangles > 0 || defaultEnvironment)
    std::printf(
        "%s kept out of the members; up to %d extra camera rays per pixel where the "
        "samples disagree on it (--emission-samples)\n",
        emissiveTriangles > 0 ? "emissive surfaces seen directly or in mirrors" : "the background",
        RenderOptions{}.emissionSamples);
  else
    std::printf("none unless --env or --background (no emission pass)\n");
}

// What a render for the members of `list` (the --denoise value of `chorus render` that `stage` was
// parsed from) records, writes and leaves out.
void printDenoising(const DenoiseStage& stage, const std::string& list) {
  const BufferPlanes planes = stage.planesNeeded();
  std::string label = stage.enabled() ? stage.label() : "none";
  if (list == "default" || list == "preview") label += " (" + list + ")";
  if (!stage.enabled()) label += " (render.exr for the default members of a later chorus denoise)";
  std::printf("denoising   %s: %d sub-buffer(s)\n", label.c_str(), stage.splitsNeeded());
  std::printf("  records   colour, %s\n", joined(planes.names()).c_str());
  std::printf("  left out  %s\n", joined(BufferPlanes::all().minus(planes).names()).c_str());
  std::vector<std::string> files = {"render.exr", "color.png"};
  for (const std::string& f : stage.files()) files.push_back(f);
  files.push_back("stats.json");
  std::printf("  writes    %s\n", joined(files).c_str());
  std::vector<std::string> kept;
  for (const LeftOut& l : stage.leftOut()) kept.push_back(l.file + " (" + l.how + ")");
  if (!kept.empty()) std::printf("  only with %s\n", joined(kept).c_str());
}

void runInfo(const std::string& path, const std::string& methods) {
  // Parsed first: an unknown member is refused before anything is printed.
  const DenoiseStage stage = DenoiseStage::parse(methods, CombineOptions{}, true);
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
  printNeeds(scene, emissiveTriangles);
  printDenoising(stage, methods);
  for (const std::string& w : scene.warnings) std::cerr << "chorus: warning: " << w << "\n";
}

const RegisterCommand infoCommand(20, [](CLI::App& app) {
  auto path = std::make_shared<std::string>();
  auto methods = std::make_shared<std::string>("default");
  CLI::App* cmd = app.add_subcommand(
      "info",
      "Summarise a glTF scene: triangles, materials and their features, lights, cameras, "
      "bounds, what of the renderer it needs, and what a render for --methods records, writes "
      "and leaves out");
  cmd->add_option("scene", *path, "glTF scene (.gltf or .glb)")->required();
  cmd->add_option("--methods", *methods,
                  "The members of a later `chorus render --denoise`: default, preview, none or a "
                  "comma-separated list of base denoisers")
      ->capture_default_str();
  cmd->callback([path, methods] { runInfo(*path, *methods); });
});

}  // namespace
}  // namespace chorus::cli
