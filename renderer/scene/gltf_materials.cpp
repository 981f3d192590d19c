#include "renderer/scene/gltf_materials.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <tbb/parallel_for.h>

#include "common/error.h"
#include "renderer/scene/scene_limits.h"
#include "renderer/scene/texture.h"

namespace chorus::render::gltf {
namespace {

const tinygltf::Value* findExtension(const tinygltf::ExtensionMap& extensions, const char* name) {
  const auto it = extensions.find(name);
  return it == extensions.end() || !it->second.IsObject() ? nullptr : &it->second;
}

double number(const tinygltf::Value& object, const char* key, double fallback) {
  if (!object.Has(key)) return fallback;
  const tinygltf::Value& v = object.Get(key);
  return v.IsNumber() ? v.GetNumberAsDouble() : fallback;
}

// A double from the file as a float, clamped to the finite floats (1e39 would become +inf, and
// inf · 0 makes NaN downstream); non-finite values become 0.
float finiteFloat(double v) {
  constexpr double kLargest = std::numeric_limits<float>::max();
  return std::isfinite(v) ? float(std::clamp(v, -kLargest, kLargest)) : 0.0f;
}

Rgb color3(const tinygltf::Value& object, const char* key, Rgb fallback) {
  if (!object.Has(key)) return fallback;
  const tinygltf::Value& v = object.Get(key);
  if (!v.IsArray() || v.ArrayLen() < 3) return fallback;
  Rgb c;
  for (int i = 0; i < 3; ++i)
    c[i] = v.Get(i).IsNumber() ? finiteFloat(v.Get(i).GetNumberAsDouble()) : 0;
  return c;
}

struct TextureRef {
  int index = -1, texCoord = 0;
};

TextureRef textureInfo(const tinygltf::Value& object, const char* key) {
  if (!object.Has(key) || !object.Get(key).IsObject()) return {};
  const tinygltf::Value& info = object.Get(key);
  return {int(number(info, "index", -1)), int(number(info, "texCoord", 0))};
}

Rgb rgbFrom(const std::vector<double>& v, Rgb fallback) {
  if (v.size() < 3) return fallback;
  return {float(v[0]), float(v[1]), float(v[2])};
}

WrapMode wrapMode(int glWrap) {
  switch (glWrap) {
    case TINYGLTF_TEXTURE_WRAP_CLAMP_TO_EDGE:
      return WrapMode::ClampToEdge;
    case TINYGLTF_TEXTURE_WRAP_MIRRORED_REPEAT:
      return WrapMode::MirroredRepeat;
    default:
      return WrapMode::Repeat;
  }
}

// Factors are clamped to their glTF ranges so that a bad file cannot create energy.
float clamp01(double v) {
  return float(std::clamp(std::isfinite(v) ? v : 0.0, 0.0, 1.0));
}
Rgb clampColor01(Rgb c) {
  return {clamp01(c.r), clamp01(c.g), clamp01(c.b)};
}

}  // namespace

void MaterialReader::warnOnce(const std::string& line) {
  if (std::find(out_.warnings.begin(), out_.warnings.end(), line) == out_.warnings.end())
    out_.warnings.push_back(line);
}

int MaterialReader::materialIndex(int gltfIndex) {
  if (gltfIndex >= 0 && size_t(gltfIndex) >= model_.materials.size())
    throw Error("a primitive refers to missing material " + std::to_string(gltfIndex));
  const auto it = materials_.find(gltfIndex);
  if (it != materials_.end()) return it->second;
  MaterialDesc m;
  if (gltfIndex < 0) {
    // glTF 2.0 §3.9.6: the default material is metallic 1, roughness 1, white.
    m.name = "default";
  } else {
    m = convert(model_.materials[size_t(gltfIndex)], gltfIndex);
  }
  const int index = int(out_.materials.size());
  out_.materials.push_back(std::move(m));
  materials_[gltfIndex] = index;
  return index;
}

MaterialDesc MaterialReader::convert(const tinygltf::Material& gm, int gltfIndex) {
  MaterialDesc m;
  m.name = gm.name.empty() ? "material " + std::to_string(gltfIndex) : "'" + gm.name + "'";
  const std::string label = gm.name.empty() ? m.name : "material " + m.name;
  const tinygltf::PbrMetallicRoughness& pbr = gm.pbrMetallicRoughness;

  if (pbr.baseColorFactor.size() >= 4) {
    m.baseColor = clampColor01(rgbFrom(pbr.baseColorFactor, Rgb(1.0f)));
    m.alpha = clamp01(pbr.baseColorFactor[3]);
  }
  m.baseColorTexture = texture(pbr.baseColorTexture.index, pbr.baseColorTexture.texCoord,
                               label + " baseColorTexture");
  m.metallic = clamp01(pbr.metallicFactor);
  m.roughness = clamp01(pbr.roughnessFactor);
  m.metallicRoughnessTexture =
      texture(pbr.metallicRoughnessTexture.index, pbr.metallicRoughnessTexture.texCoord,
              label + " metallicRoughnessTexture");
  m.normalTexture =
      texture(gm.normalTexture.index, gm.normalTexture.texCoord, label + " normalTexture");
  m.normalScale = std::isfinite(gm.normalTexture.scale) ? float(gm.normalTexture.scale) : 1.0f;

  float emissiveStrength = 1.0f;
  if (const tinygltf::Value* ext =
          findExtension(gm.extensions, "KHR_materials_emissive_strength")) {
    const double strength = number(*ext, "emissiveStrength", 1.0);
    if (!(std::abs(strength) <= double(kMaxRadiance)))
      throw Error(label + " has emissiveStrength " + shortNumber(strength) +
                  ", outside the supported range of ±" + shortNumber(kMaxRadiance));
    emissiveStrength = float(std::max(0.0, strength));
  }
  m.emissive = clampColor01(rgbFrom(gm.emissiveFactor, Rgb(0.0f))) * emissiveStrength;
  if (m.isEmissive())
    m.emissiveTexture =
        texture(gm.emissiveTexture.index, gm.emissiveTexture.texCoord, label + " emissiveTexture");

  if (const tinygltf::Value* ext = findExtension(gm.extensions, "KHR_materials_transmission")) {
    m.transmission = clamp01(number(*ext, "transmissionFactor", 0.0));
    const TextureRef t = textureInfo(*ext, "transmissionTexture");
    if (m.transmission > 0)
      m.transmissionTexture = texture(t.index, t.texCoord, label + " transmissionTexture");
  }
  if (const tinygltf::Value* ext = findExtension(gm.extensions, "KHR_materials_ior")) {
    const double ior = number(*ext, "ior", 1.5);
    // ior = 0 is the spec's "infinitely reflective" special case; treat values below 1 as 1.
    m.ior = float(std::isfinite(ior) ? std::max(1.0, ior) : 1.5);
  }
  if (const tinygltf::Value* ext = findExtension(gm.extensions, "KHR_materials_specular")) {
    m.specular = clamp01(number(*ext, "specularFactor", 1.0));
    // specularColorFactor may exceed 1 (it is clamped with the Fresnel term by the BSDF).
    const Rgb sc = color3(*ext, "specularColorFactor", Rgb(1.0f));
    m.specularColor = {std::max(0.0f, sc.r), std::max(0.0f, sc.g), std::max(0.0f, sc.b)};
    const TextureRef st = textureInfo(*ext, "specularTexture");
    const TextureRef sct = textureInfo(*ext, "specularColorTexture");
    if (m.specular > 0) {
      m.specularTexture = texture(st.index, st.texCoord, label + " specularTexture");
      m.specularColorTexture = texture(sct.index, sct.texCoord, label + " specularColorTexture");
    }
  }
  if (const tinygltf::Value* ext = findExtension(gm.extensions, "KHR_materials_volume")) {
    // thicknessFactor 0 means thin-walled (spec); the thickness itself is only a rasteriser's
    // approximation of the geometry we trace, so it is not kept.
    m.hasVolume = number(*ext, "thicknessFactor", 0.0) > 0;
    m.attenuationColor = clampColor01(color3(*ext, "attenuationColor", Rgb(1.0f)));
    const double distance = number(*ext, "attenuationDistance", 0.0);
    if (distance > 0 && std::isfinite(distance)) m.attenuationDistance = float(distance);
  }

  if (gm.alphaMode == "MASK") {
    m.alphaMode = AlphaMode::Mask;
    m.alphaCutoff = float(std::isfinite(gm.alphaCutoff) ? gm.alphaCutoff : 0.5);
  } else if (gm.alphaMode == "BLEND") {
    m.alphaMode = AlphaMode::Blend;
  }
  m.doubleSided = gm.doubleSided;
  return m;
}

int MaterialReader::texture(int gltfIndex, int texCoord, const std::string& what) {
  if (gltfIndex < 0) return -1;
  if (size_t(gltfIndex) >= model_.textures.size())
    throw Error(what + " refers to missing texture " + std::to_string(gltfIndex));
  if (texCoord != 0)
    warnOnce(what + " uses TEXCOORD_" + std::to_string(texCoord) +
             "; chorus reads TEXCOORD_0 for every texture");
  const auto it = textures_.find(gltfIndex);
  if (it != textures_.end()) return it->second;

  const tinygltf::Texture& gt = model_.textures[size_t(gltfIndex)];
  if (gt.source < 0)
    throw Error("texture " + std::to_string(gltfIndex) + " has no image source" +
                (gt.extensions.empty() ? "" : " chorus can read (only PNG/JPEG images)"));
  TextureDesc t;
  t.image = image(gt.source);
  if (gt.sampler >= 0) {
    if (size_t(gt.sampler) >= model_.samplers.size())
      throw Error("texture " + std::to_string(gltfIndex) + " refers to missing sampler " +
                  std::to_string(gt.sampler));
    const tinygltf::Sampler& s = model_.samplers[size_t(gt.sampler)];
    t.wrapS = wrapMode(s.wrapS);
    t.wrapT = wrapMode(s.wrapT);
    t.nearest = s.magFilter == TINYGLTF_TEXTURE_FILTER_NEAREST;
  }
  const int index = int(out_.textures.size());
  out_.textures.push_back(t);
  textures_[gltfIndex] = index;
  return index;
}

int MaterialReader::image(int gltfIndex) {
  if (size_t(gltfIndex) >= model_.images.size())
    throw Error("a texture refers to missing image " + std::to_string(gltfIndex));
  const auto it = images_.find(gltfIndex);
  if (it != images_.end()) return it->second;
  const tinygltf::Image& gi = model_.images[size_t(gltfIndex)];
  const std::string name = !gi.uri.empty() && gi.uri.rfind("data:", 0) != 0
                               ? gi.uri
                               : "image " + std::to_string(gltfIndex);
  if (gi.image.empty()) {
    if (!gi.uri.empty()) throw Error("texture image '" + gi.uri + "' is missing or empty");
    throw Error("image " + std::to_string(gltfIndex) + " has no data");
  }
  const int index = int(out_.images.size());
  out_.images.push_back({});
  out_.images.back().name = name;
  pendingImages_.push_back(&gi);
  images_[gltfIndex] = index;
  return index;
}

void MaterialReader::decodeImages() {
  std::vector<std::string> errors(pendingImages_.size());
  tbb::parallel_for(size_t(0), pendingImages_.size(), [&](size_t i) {
    try {
      out_.images[i] = decodeImage(pendingImages_[i]->image, out_.images[i].name);
    } catch (const Error& e) {
      errors[i] = e.what();
    }
  });
  pendingImages_.clear();
  // The first bad image in the file's order, whichever thread saw it first.
  for (const std::string& error : errors)
    if (!error.empty()) throw Error(error);
}

}  // namespace chorus::render::gltf
