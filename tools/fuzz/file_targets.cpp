#include "tools/fuzz/file_targets.h"

#include <nlohmann/json.hpp>

#include <cmath>

#include "common/error.h"
#include "common/image/exr_io.h"
#include "denoise/buffers/buffers_exr.h"
#include "denoise/buffers/tungsten_dir.h"
#include "renderer/render.h"
#include "renderer/scene/environment.h"
#include "renderer/scene/gltf_loader.h"
#include "renderer/scene/scene.h"
#include "tools/fuzz/byte_mutations.h"
#include "tools/fuzz/exr_mutations.h"
#include "tools/fuzz/glb.h"
#include "tools/fuzz/gltf_mutations.h"
#include "tools/fuzz/radiance_hdr.h"

namespace chorus::fuzz {
namespace fs = std::filesystem;
using namespace chorus::render;

namespace {

bool hasExtension(const std::string& name, std::initializer_list<const char*> extensions) {
  const std::string ext = fs::path(name).extension().string();
  for (const char* e : extensions)
    if (ext == e) return true;
  return false;
}

// The case's main input: the first file with one of these extensions.
fs::path mainFile(const FuzzCase& fuzzCase, const fs::path& caseDir,
                  std::initializer_list<const char*> extensions) {
  for (const CaseFile& file : fuzzCase.files)
    if (hasExtension(file.name, extensions)) return caseDir / file.name;
  throw Error("fuzz: the case has no input file");
}

// ---- generation ------------------------------------------------------------------------------

std::string structuralGltfEdits(const std::string& main, bool glb, int edits, FuzzCase& fuzzCase,
                                FuzzRandom& rng) {
  std::optional<GlbParts> parts;
  if (glb) parts = unpackGlb(main);
  nlohmann::json doc = nlohmann::json::parse(glb ? parts->json : main);
  GltfEditor editor(std::move(doc));
  for (int i = 0; i < edits; ++i) {
    try {
      fuzzCase.mutations.push_back(editor.randomEdit(rng));
    } catch (const std::exception&) {  // the edit met a value an earlier edit had replaced
      fuzzCase.mutations.push_back("(an edit found nothing to change)");
    }
  }
  for (const std::string& fifo : editor.fifos()) fuzzCase.files.push_back({fifo, "", true});
  if (!glb) return editor.text();
  parts->json = editor.text();
  return packGlb(*parts);
}

void generateGltf(const SeedCorpus& seeds, FuzzRandom& rng, FuzzCase& fuzzCase) {
  const SeedInput& seed = rng.pick(seeds.gltf);
  fuzzCase.files = seed.files;
  const bool glb = hasExtension(seed.files[0].name, {".glb"});
  fuzzCase.files[0].name = glb ? "scene.glb" : "scene.gltf";
  fuzzCase.mutations.push_back("seed " + seed.name);
  const int edits = int(1 + rng.below(3));
  // files[0] is re-read after every step: the edits may add files (FIFOs).
  if (rng.chance(0.65)) {
    std::string edited = structuralGltfEdits(fuzzCase.files[0].bytes, glb, edits, fuzzCase, rng);
    fuzzCase.files[0].bytes = std::move(edited);
    if (rng.chance(0.15)) fuzzCase.mutations.push_back(mutateBytes(fuzzCase.files[0].bytes, rng));
  } else {
    for (int i = 0; i < edits; ++i)
      fuzzCase.mutations.push_back(mutateBytes(fuzzCase.files[0].bytes, rng));
  }
  if (fuzzCase.files.size() > 1 && rng.chance(0.1)) {
    CaseFile& other = fuzzCase.files[1 + rng.below(fuzzCase.files.size() - 1)];
    if (!other.fifo)
      fuzzCase.mutations.push_back(other.name + ": " + mutateBytes(other.bytes, rng));
  }
}

void generateExr(const SeedCorpus& seeds, FuzzRandom& rng, FuzzCase& fuzzCase) {
  const SeedInput& seed = rng.pick(seeds.exr);
  fuzzCase.files = seed.files;
  fuzzCase.mutations.push_back("seed " + seed.name);
  const int edits = int(1 + rng.below(3));
  if (!seed.directory) {
    for (int i = 0; i < edits; ++i)
      fuzzCase.mutations.push_back(rng.chance(0.6) ? mutateExrFields(fuzzCase.files[0].bytes, rng)
                                                   : mutateBytes(fuzzCase.files[0].bytes, rng));
    return;
  }
  // A Tungsten directory: edit meta.json, drop or swap a file, or edit one EXR.
  auto& files = fuzzCase.files;
  const auto meta = std::find_if(files.begin(), files.end(),
                                 [](const CaseFile& f) { return f.name == "meta.json"; });
  const size_t roll = rng.below(10);
  if (roll < 3 && meta != files.end()) {
    GltfEditor editor(nlohmann::json::parse(meta->bytes));
    fuzzCase.mutations.push_back(
        "meta.json: " + (rng.chance(0.7) ? editor.extremeNumber(rng) : editor.duplicateKey(rng)));
    meta->bytes = editor.text();
  } else if (roll == 3) {
    const size_t i = rng.below(files.size());
    fuzzCase.mutations.push_back("remove " + files[i].name);
    files.erase(files.begin() + std::ptrdiff_t(i));
  } else if (roll == 4) {
    const size_t i = rng.below(files.size()), j = rng.below(files.size());
    fuzzCase.mutations.push_back(files[i].name + " replaced by " + files[j].name);
    files[i].bytes = files[j].bytes;
  } else {
    CaseFile& file = files[rng.below(files.size())];
    for (int i = 0; i < edits; ++i)
      fuzzCase.mutations.push_back(
          file.name + ": " +
          (rng.chance(0.6) ? mutateExrFields(file.bytes, rng) : mutateBytes(file.bytes, rng)));
  }
}

void generateEnvironment(const SeedCorpus& seeds, FuzzRandom& rng, FuzzCase& fuzzCase) {
  const SeedInput& seed = rng.pick(seeds.environment);
  fuzzCase.files = seed.files;
  fuzzCase.mutations.push_back("seed " + seed.name);
  CaseFile& main = fuzzCase.files[0];
  const bool hdr = hasExtension(main.name, {".hdr"});
  const int edits = int(1 + rng.below(2));
  for (int i = 0; i < edits; ++i) {
    if (rng.chance(0.6))
      fuzzCase.mutations.push_back(hdr ? mutateRadianceHdr(main.bytes, rng)
                                       : mutateExrFields(main.bytes, rng));
    else
      fuzzCase.mutations.push_back(mutateBytes(main.bytes, rng));
  }
}

// ---- checks ----------------------------------------------------------------------------------

std::string nonFinite(const Image& image, const std::string& what) {
  for (const float v : image.values())
    if (!std::isfinite(v)) return "non-finite value in " + what;
  return "";
}

std::string bufferProblems(const SampleBuffers& buffers) {
  for (int k = 0; k < buffers.splitCount(); ++k) {
    const SubBuffer& sub = buffers.sub(k);
    for (const Quantity q : kAllQuantities) {
      const std::string name =
          "sub-buffer " + std::to_string(k) + " " + std::string(quantityName(q));
      if (std::string p = nonFinite(sub.get(q).mean, name + " mean"); !p.empty()) return p;
      if (std::string p = nonFinite(sub.get(q).varianceOfMean, name + " variance"); !p.empty())
        return p;
    }
  }
  return "";
}

// What the rest of the renderer relies on without checking (renderer/scene/scene_desc.h).
std::string sceneDescProblems(const SceneDesc& desc) {
  const auto textureOk = [&](int t) { return t >= -1 && t < int(desc.textures.size()); };
  for (const MeshDesc& mesh : desc.meshes) {
    const size_t n = mesh.positions.size();
    if (mesh.indices.size() % 3 != 0) return mesh.name + ": index count not a multiple of 3";
    for (const uint32_t i : mesh.indices)
      if (i >= n)
        return mesh.name + ": index " + std::to_string(i) + " >= " + std::to_string(n) +
               " vertices";
    if ((!mesh.normals.empty() && mesh.normals.size() != n) ||
        (!mesh.uvs.empty() && mesh.uvs.size() != n) ||
        (!mesh.tangents.empty() && mesh.tangents.size() != n))
      return mesh.name + ": per-vertex arrays of different lengths";
    if (mesh.material < 0 || size_t(mesh.material) >= desc.materials.size())
      return mesh.name + ": material " + std::to_string(mesh.material) + " out of range";
  }
  for (const MaterialDesc& m : desc.materials)
    for (const int t :
         {m.baseColorTexture, m.metallicRoughnessTexture, m.normalTexture, m.emissiveTexture,
          m.transmissionTexture, m.specularTexture, m.specularColorTexture})
      if (!textureOk(t))
        return "material " + m.name + ": texture " + std::to_string(t) + " out of range";
  for (const TextureDesc& t : desc.textures)
    if (t.image < 0 || size_t(t.image) >= desc.images.size()) return "texture image out of range";
  for (const ImageDesc& image : desc.images)
    if (image.width < 1 || image.height < 1 ||
        image.rgba.size() != size_t(image.width) * size_t(image.height) * 4)
      return "image " + image.name + ": pixel array does not match its size";
  return "";
}

RenderOptions tinyRender() {
  RenderOptions options;
  options.width = 8;
  options.height = 8;
  options.spp = 1;
  options.splits = 1;
  options.threads = 1;
  return options;
}

std::string checkGltf(const fs::path& path) {
  SceneDesc desc = loadGltf(path);
  if (std::string p = sceneDescProblems(desc); !p.empty()) return p;
  // What `chorus info` reads.
  size_t emissive = 0;
  for (const MeshDesc& mesh : desc.meshes)
    emissive += desc.materials[size_t(mesh.material)].isEmissive() ? mesh.triangleCount() : 0;
  (void)emissive;
  (void)desc.bounds.diagonal();
  const Scene scene = buildScene(std::move(desc), EnvironmentDesc{});
  return bufferProblems(render::render(scene, tinyRender()).buffers);
}

std::string checkSampleBuffers(const SampleBuffers& buffers) {
  const int k = buffers.splitCount();
  if (k != 1 && k != 2 && k != 4) return "sample buffers with K = " + std::to_string(k);
  for (const SubBuffer& sub : buffers.subBuffers()) {
    for (const Quantity q : kAllQuantities) {
      const MeanVariance& mv = sub.get(q);
      if (mv.mean.width() != buffers.width() || mv.mean.height() != buffers.height() ||
          !mv.mean.sameShape(mv.varianceOfMean) || mv.mean.channels() != channelCount(q))
        return std::string(quantityName(q)) + " planes of inconsistent shapes";
    }
    for (const float n : sub.sampleCount.values())
      if (!(n >= 0) || !std::isfinite(n)) return "sample count " + std::to_string(n) + " accepted";
  }
  // Added to every output image: finite and non-negative, or rejected.
  for (const float e : buffers.emission().values())
    if (!(e >= 0) || !std::isfinite(e)) return "emission " + std::to_string(e) + " accepted";
  return "";
}

std::string checkExr(const fs::path& path) {
  const std::vector<ExrLayer> layers = readExr(path);
  for (const ExrLayer& layer : layers) {
    const Image& image = layer.image;
    if (image.size() != image.pixelCount() * size_t(image.channels()))
      return "layer '" + layer.name + "' has a pixel array that does not match its size";
  }
  // Each reader on its own: an Error from one (a missing layer) says nothing about the next.
  const auto tryRead = [](const auto& read) -> std::string {
    try {
      return read();
    } catch (const Error&) {
      return "";
    }
  };
  std::string problem = tryRead([&] {
    (void)readExrLayer(path);
    return std::string();
  });
  if (problem.empty())
    problem = tryRead([&] {
      (void)readRgbExr(path);
      return std::string();
    });
  if (problem.empty())
    problem = tryRead([&] { return checkSampleBuffers(sampleBuffersFromLayers(layers, path)); });
  return problem;
}

std::string checkTungsten(const fs::path& dir) {
  const DenoiseInput input = readTungstenDirectory(dir);
  std::vector<const SubBuffer*> parts = {&input.whole};
  if (input.halves)
    for (const SubBuffer& half : *input.halves) parts.push_back(&half);
  for (const SubBuffer* sub : parts)
    for (const float n : sub->sampleCount.values())
      if (!(n >= 0) || !std::isfinite(n)) return "sample count " + std::to_string(n) + " accepted";
  return "";
}

// A floor under the map, seen from above the horizon: sky and lit ground in 8×8 pixels.
SceneDesc floorScene() {
  SceneDesc desc;
  desc.source = "fuzz floor";
  MaterialDesc grey;
  grey.name = "grey";
  grey.baseColor = Rgb(0.5f);
  grey.metallic = 0;
  grey.doubleSided = true;
  desc.materials.push_back(grey);
  MeshDesc floor;
  floor.name = "floor";
  floor.positions = {{-5, 0, -5}, {5, 0, -5}, {5, 0, 5}, {-5, 0, 5}};
  floor.indices = {0, 2, 1, 0, 3, 2};
  for (const Vec3f& p : floor.positions) desc.bounds.extend(p);
  desc.meshes.push_back(floor);
  CameraDesc camera;
  camera.name = "above";
  camera.position = {0, 1, 4};
  camera.forward = normalize(Vec3f(0, -0.25f, -1));
  camera.right = normalize(cross(camera.forward, Vec3f(0, 1, 0)));
  camera.up = cross(camera.right, camera.forward);
  desc.cameras.push_back(camera);
  return desc;
}

std::string checkEnvironment(const fs::path& path) {
  const Image image = loadEnvironmentImage(path);
  for (const float v : image.values())
    if (!(v >= 0) || !std::isfinite(v)) return "texel " + std::to_string(v) + " passed through";
  const EnvironmentDesc environment = environmentFromFile(path, 30.0f, 1.0f);
  const Scene scene = buildScene(floorScene(), environment);
  return bufferProblems(render::render(scene, tinyRender()).buffers);
}

}  // namespace

FuzzCase generateFileCase(Target target, const SeedCorpus& seeds, FuzzRandom& rng) {
  FuzzCase fuzzCase;
  fuzzCase.target = target;
  switch (target) {
    case Target::Gltf:
      generateGltf(seeds, rng, fuzzCase);
      break;
    case Target::Exr:
      generateExr(seeds, rng, fuzzCase);
      break;
    case Target::Environment:
      generateEnvironment(seeds, rng, fuzzCase);
      break;
    case Target::Cli:
      throw Error("fuzz: the CLI target has no file cases");
  }
  return fuzzCase;
}

std::string checkFileCase(const FuzzCase& fuzzCase, const fs::path& caseDir) {
  switch (fuzzCase.target) {
    case Target::Gltf:
      return checkGltf(mainFile(fuzzCase, caseDir, {".gltf", ".glb"}));
    case Target::Exr:
      for (const CaseFile& file : fuzzCase.files)
        if (file.name == "color.exr" || file.name == "meta.json") return checkTungsten(caseDir);
      return checkExr(mainFile(fuzzCase, caseDir, {".exr"}));
    case Target::Environment:
      return checkEnvironment(mainFile(fuzzCase, caseDir, {".hdr", ".pic", ".exr"}));
    case Target::Cli:
      break;
  }
  throw Error("fuzz: the CLI target has no file cases");
}

}  // namespace chorus::fuzz
