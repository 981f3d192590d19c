#include "tools/fuzz/gltf_mutations.h"

#include <cctype>
#include <map>

namespace chorus::fuzz {
namespace {

using nlohmann::json;
using Pointer = json::json_pointer;

// Where a number is an index, and into which top-level array.
const std::map<std::string, std::string>& indexKeys() {
  static const std::map<std::string, std::string> keys = {
      {"mesh", "meshes"},          {"camera", "cameras"},
      {"material", "materials"},   {"indices", "accessors"},
      {"POSITION", "accessors"},   {"NORMAL", "accessors"},
      {"TEXCOORD_0", "accessors"}, {"TANGENT", "accessors"},
      {"COLOR_0", "accessors"},    {"bufferView", "bufferViews"},
      {"buffer", "buffers"},       {"source", "images"},
      {"sampler", "samplers"},     {"index", "textures"},
      {"children", "nodes"},       {"nodes", "nodes"},
      {"scene", "scenes"},         {"light", "lights"}};
  return keys;
}

// Fields worth setting to extremes, per top-level array (paths inside one element).
const std::map<std::string, std::vector<std::string>>& checkedFields() {
  static const std::map<std::string, std::vector<std::string>> fields = {
      {"accessors",
       {"count", "byteOffset", "componentType", "type", "bufferView", "normalized", "min",
        "sparse/count", "sparse/indices/bufferView", "sparse/indices/byteOffset",
        "sparse/indices/componentType", "sparse/values/bufferView", "sparse/values/byteOffset"}},
      {"bufferViews", {"buffer", "byteOffset", "byteLength", "byteStride"}},
      {"buffers", {"byteLength", "uri"}},
      {"nodes", {"mesh", "camera", "children", "matrix", "translation", "rotation", "scale"}},
      {"meshes",
       {"primitives/0/mode", "primitives/0/indices", "primitives/0/material",
        "primitives/0/attributes/POSITION", "primitives/0/attributes/NORMAL",
        "primitives/0/attributes/TEXCOORD_0", "primitives/0/attributes/TANGENT", "primitives"}},
      {"cameras",
       {"type", "perspective/yfov", "perspective/znear", "perspective/zfar",
        "perspective/aspectRatio", "orthographic/xmag", "orthographic/ymag", "orthographic/znear"}},
      {"materials",
       {"pbrMetallicRoughness/baseColorFactor", "pbrMetallicRoughness/metallicFactor",
        "pbrMetallicRoughness/roughnessFactor", "pbrMetallicRoughness/baseColorTexture/index",
        "pbrMetallicRoughness/baseColorTexture/texCoord", "normalTexture/index",
        "normalTexture/scale", "emissiveFactor", "emissiveTexture/index", "alphaMode",
        "alphaCutoff", "extensions/KHR_materials_emissive_strength/emissiveStrength",
        "extensions/KHR_materials_transmission/transmissionFactor",
        "extensions/KHR_materials_ior/ior", "extensions/KHR_materials_volume/thicknessFactor",
        "extensions/KHR_materials_volume/attenuationDistance",
        "extensions/KHR_materials_specular/specularFactor"}},
      {"images", {"uri", "bufferView", "mimeType"}},
      {"textures", {"source", "sampler"}},
      {"samplers", {"magFilter", "minFilter", "wrapS", "wrapT"}},
      {"scenes", {"nodes"}},
  };
  return fields;
}

const std::vector<std::string>& badUris() {
  static const std::vector<std::string> uris = {"",
                                                ".",
                                                "..",
                                                "/",
                                                "/dev/zero",
                                                "/dev/null",
                                                "/dev/urandom",
                                                "/proc/self/mem",
                                                "missing.bin",
                                                "sub/../../missing.bin",
                                                "%2e%2e/x.bin",
                                                "data:",
                                                "data:application/octet-stream;base64,",
                                                "data:application/octet-stream;base64,AAAA",
                                                "data:application/octet-stream;base64,!!!!",
                                                "data:application/octet-stream,abc",
                                                "data:,hello",
                                                "data:image/png;base64,iVBORw0KGgo=",
                                                "file:///etc/passwd",
                                                "http://example.invalid/x.bin",
                                                std::string(4096, 'a'),
                                                "fifo.bin"};
  return uris;
}

struct Sites {
  std::vector<Pointer> numbers, objects, arrays, indices;
};

void collect(const json& j, const Pointer& at, const std::string& key, Sites& sites) {
  if (j.is_number()) {
    sites.numbers.push_back(at);
    if (indexKeys().count(key)) sites.indices.push_back(at);
  } else if (j.is_object()) {
    sites.objects.push_back(at);
    for (const auto& [k, v] : j.items()) collect(v, at / k, k, sites);
  } else if (j.is_array()) {
    sites.arrays.push_back(at);
    for (size_t i = 0; i < j.size(); ++i) collect(j[i], at / i, key, sites);
  }
}

Sites sitesOf(const json& doc) {
  Sites sites;
  collect(doc, Pointer(), "", sites);
  return sites;
}

size_t arraySize(const json& doc, const std::string& name) {
  if (name == "lights") {
    const Pointer p("/extensions/KHR_lights_punctual/lights");
    return doc.contains(p) && doc[p].is_array() ? doc[p].size() : 0;
  }
  return doc.contains(name) && doc[name].is_array() ? doc[name].size() : 0;
}

}  // namespace

const std::vector<std::string>& extremeLiterals() {
  static const std::vector<std::string> literals = {"-1",
                                                    "0",
                                                    "1",
                                                    "2147483647",
                                                    "2147483648",
                                                    "-2147483649",
                                                    "4294967295",
                                                    "4294967296",
                                                    "4611686018427387904",
                                                    "9223372036854775807",
                                                    "9223372036854775808",
                                                    "18446744073709551615",
                                                    "18446744073709551616",
                                                    "6148914691236517206",
                                                    "1e20",
                                                    "-1e20",
                                                    "1e-30",
                                                    "1e38",
                                                    "3.5e38",
                                                    "1e308",
                                                    "1e309",
                                                    "-1e309",
                                                    "1e-400",
                                                    "-0",
                                                    "0.5",
                                                    "NaN",
                                                    "Infinity",
                                                    "-Infinity",
                                                    "1e",
                                                    "0x10",
                                                    "\"12\"",
                                                    "null",
                                                    "true",
                                                    "[]",
                                                    "{}",
                                                    "123456789012345678901234567890"};
  return literals;
}

std::string GltfEditor::placeholder(std::string literal) {
  std::string name = "@@fuzz" + std::to_string(literals_.size()) + "@@";
  literals_.emplace_back(name, std::move(literal));
  return name;
}

std::string GltfEditor::text() const {
  std::string text = doc_.dump(1);
  for (const auto& [name, literal] : literals_) {
    const std::string quoted = "\"" + name + "\"";
    for (size_t at = text.find(quoted); at != std::string::npos; at = text.find(quoted, at)) {
      text.replace(at, quoted.size(), literal);
      at += literal.size();
    }
  }
  return text;
}

json GltfEditor::randomValue(FuzzRandom& rng, const std::string& key) {
  if (key == "uri") {
    const std::string& uri = rng.pick(badUris());
    if (uri == "fifo.bin") fifos_.push_back(uri);
    return uri;
  }
  switch (rng.below(6)) {
    case 0:
    case 1:
    case 2:
      return placeholder(rng.pick(extremeLiterals()));
    case 3: {  // a vector with one extreme component, or of the wrong length
      json a = json::array();
      const size_t n = rng.below(18);
      for (size_t i = 0; i < n; ++i)
        a.push_back(i == 0 ? json(placeholder(rng.pick(extremeLiterals()))) : json(0.5));
      return a;
    }
    case 4:
      return rng.pick(std::vector<std::string>{"VEC3", "MAT4", "VEC5", "", "SCALAR", "BLEND",
                                               "MASK", "orthographic", "perspective", "x"});
    default:
      return json::object({{"a", placeholder(rng.pick(extremeLiterals()))}});
  }
}

std::string GltfEditor::extremeNumber(FuzzRandom& rng) {
  const Sites sites = sitesOf(doc_);
  if (sites.numbers.empty()) return targetedField(rng);
  const Pointer& at = rng.pick(sites.numbers);
  const std::string literal = rng.pick(extremeLiterals());
  doc_[at] = placeholder(literal);
  return at.to_string() + " = " + literal;
}

std::string GltfEditor::targetedField(FuzzRandom& rng) {
  std::vector<std::string> present;
  for (const auto& [name, fields] : checkedFields())
    if (arraySize(doc_, name) > 0) present.push_back(name);
  if (present.empty()) return deleteKey(rng);
  const std::string& array = rng.pick(present);
  const size_t element = rng.below(arraySize(doc_, array));
  const std::string& field = rng.pick(checkedFields().at(array));
  const Pointer at = Pointer("/" + array) / element / Pointer("/" + field);
  const std::string key = field.substr(field.rfind('/') + 1);
  doc_[at] = randomValue(rng, key);
  std::string shown = doc_[at].dump();
  for (const auto& [name, literal] : literals_)
    if (shown.find(name) != std::string::npos) shown = literal.substr(0, 40);
  return at.to_string() + " = " + shown;
}

std::optional<std::pair<Pointer, std::string>> GltfEditor::pickKey(FuzzRandom& rng) const {
  const Sites sites = sitesOf(doc_);
  for (int attempt = 0; attempt < 8; ++attempt) {
    const Pointer& at = rng.pick(sites.objects);
    const json& object = doc_[at];
    if (object.empty()) continue;
    auto it = object.begin();
    std::advance(it, rng.below(object.size()));
    return std::pair{at, it.key()};
  }
  return std::nullopt;
}

std::string GltfEditor::deleteKey(FuzzRandom& rng) {
  const auto picked = pickKey(rng);
  if (!picked) return "delete nothing";
  const auto& [at, key] = *picked;
  doc_[at].erase(key);
  return "delete " + (at / key).to_string();
}

std::string GltfEditor::duplicateKey(FuzzRandom& rng) {
  const auto picked = pickKey(rng);
  if (!picked) return "duplicate nothing";
  const auto& [at, key] = *picked;
  // The placeholder key becomes a second "key" in the text (JSON objects cannot hold two).
  doc_[at][placeholder("\"" + key + "\"")] = randomValue(rng, key);
  return "duplicate key " + (at / key).to_string();
}

std::string GltfEditor::editArray(FuzzRandom& rng) {
  const Sites sites = sitesOf(doc_);
  const Pointer& at = rng.pick(sites.arrays);
  json& array = doc_[at];
  const std::string where = at.to_string();
  if (array.empty() || rng.chance(0.2)) {
    array.push_back(rng.chance(0.5) ? json() : randomValue(rng, ""));
    return "append to " + where;
  }
  const size_t i = rng.below(array.size());
  switch (rng.below(4)) {
    case 0:
      array.erase(i);
      return "delete " + where + "/" + std::to_string(i);
    case 1:
      array.insert(array.begin() + std::ptrdiff_t(i), array[i]);
      return "duplicate " + where + "/" + std::to_string(i);
    case 2:
      array = json::array();
      return "empty " + where;
    default: {
      const json copy = array[i];
      for (int k = 0; k < 1000 && array.size() < 5000; ++k) array.push_back(copy);
      return "repeat " + where + "/" + std::to_string(i) + " 1000 times";
    }
  }
}

std::string GltfEditor::deepNesting(FuzzRandom& rng) {
  const Sites sites = sitesOf(doc_);
  const Pointer& at = rng.pick(sites.objects);
  const size_t depth = rng.pick(std::vector<size_t>{64, 1000, 10000, 100000});
  const bool arrays = rng.chance(0.5);
  std::string literal;
  literal.reserve(depth * 6 + 1);
  for (size_t i = 0; i < depth; ++i) literal += arrays ? "[" : "{\"a\":";
  literal += "0";
  for (size_t i = 0; i < depth; ++i) literal += arrays ? "]" : "}";
  const std::string key = rng.chance(0.7) ? "extras" : "extensions";
  doc_[at][key] = placeholder(std::move(literal));
  return (at / key).to_string() + " nested " + std::to_string(depth) +
         (arrays ? " arrays" : " objects") + " deep";
}

std::string GltfEditor::crossIndex(FuzzRandom& rng) {
  const Sites sites = sitesOf(doc_);
  if (sites.indices.empty()) return targetedField(rng);
  const Pointer& at = rng.pick(sites.indices);
  const std::string key = at.back();
  const std::string& target = indexKeys().at(
      std::isdigit(static_cast<unsigned char>(key[0])) ? at.parent_pointer().back() : key);
  const auto n = int64_t(arraySize(doc_, target));
  const std::vector<int64_t> choices = {-1,
                                        n,
                                        n + 1,
                                        n > 0 ? int64_t(rng.below(size_t(n))) : 0,
                                        int64_t(arraySize(doc_, "accessors")),
                                        int64_t(arraySize(doc_, "nodes")) - 1,
                                        2147483647};
  const int64_t value = rng.pick(choices);
  doc_[at] = value;
  return at.to_string() + " = " + std::to_string(value) + " (" + target + " has " +
         std::to_string(n) + ")";
}

std::string GltfEditor::cyclicChildren(FuzzRandom& rng) {
  const size_t n = arraySize(doc_, "nodes");
  if (n == 0) return nodeDag(rng);
  const size_t i = rng.below(n), j = rng.below(n);
  doc_["nodes"][i]["children"].push_back(j);
  if (i != j) doc_["nodes"][j]["children"].push_back(i);
  return "nodes " + std::to_string(i) + " and " + std::to_string(j) + " are each other's child";
}

std::string GltfEditor::nodeDag(FuzzRandom& rng) {
  if (!doc_.contains("nodes") || !doc_["nodes"].is_array()) doc_["nodes"] = json::array();
  const size_t first = doc_["nodes"].size();
  const size_t levels = rng.pick(std::vector<size_t>{2, 8, 16, 20, 24, 30});
  for (size_t level = 0; level < levels; ++level)
    doc_["nodes"].push_back({{"children", {first + level + 1, first + level + 1}}});
  doc_["nodes"].push_back(arraySize(doc_, "meshes") ? json{{"mesh", 0}} : json::object());
  doc_["scenes"][0]["nodes"].push_back(first);
  doc_["scene"] = 0;
  return "a node DAG of " + std::to_string(levels) + " levels (each lists the next twice)";
}

std::string GltfEditor::badUri(FuzzRandom& rng) {
  const bool images = arraySize(doc_, "images") > 0 && rng.chance(0.3);
  const std::string array = images ? "images" : "buffers";
  if (arraySize(doc_, array) == 0) return targetedField(rng);
  const size_t i = rng.below(arraySize(doc_, array));
  json& element = doc_[array][i];
  element.erase("bufferView");
  element["uri"] = randomValue(rng, "uri");
  return array + "/" + std::to_string(i) + "/uri = '" +
         element["uri"].get<std::string>().substr(0, 60) + "'";
}

std::string GltfEditor::farCamera(FuzzRandom& rng) {
  json camera;
  if (rng.chance(0.5)) {
    camera = {
        {"type", "perspective"},
        {"perspective",
         {{"yfov",
           placeholder(rng.pick(std::vector<std::string>{"0.8", "1e-30", "3.2", "1e20", "-1"}))},
          {"znear", 0.01}}}};
  } else {
    camera = {
        {"type", "orthographic"},
        {"orthographic",
         {{"xmag", placeholder(rng.pick(std::vector<std::string>{"1", "1e-30", "1e20", "0"}))},
          {"ymag", placeholder(rng.pick(std::vector<std::string>{"1", "1e20", "1e-30", "-1"}))},
          {"znear", 0.01},
          {"zfar", 100}}}};
  }
  doc_["cameras"].push_back(camera);
  const std::string distance =
      rng.pick(std::vector<std::string>{"1e20", "-1e20", "1e18", "3e38", "1e10", "2"});
  doc_["nodes"].push_back(
      {{"camera", doc_["cameras"].size() - 1}, {"translation", {0, 0, placeholder(distance)}}});
  doc_["scenes"][0]["nodes"].push_back(doc_["nodes"].size() - 1);
  // The new camera first, so that a render uses it.
  doc_["nodes"].insert(doc_["nodes"].begin(), doc_["nodes"].back());
  doc_["nodes"].erase(doc_["nodes"].size() - 1);
  for (json& node : doc_["nodes"]) {
    if (node.contains("children") && node["children"].is_array())
      for (json& child : node["children"])
        if (child.is_number_integer()) child = child.get<int64_t>() + 1;
  }
  for (json& scene : doc_["scenes"])
    if (scene.contains("nodes") && scene["nodes"].is_array())
      for (json& root : scene["nodes"])
        if (root.is_number_integer())
          root = (root.get<int64_t>() + 1) % int64_t(doc_["nodes"].size());
  return camera["type"].get<std::string>() + " camera at z = " + distance;
}

std::string GltfEditor::randomEdit(FuzzRandom& rng) {
  switch (rng.below(14)) {
    case 0:
    case 1:
      return extremeNumber(rng);
    case 2:
    case 3:
    case 4:
      return targetedField(rng);
    case 5:
      return deleteKey(rng);
    case 6:
      return duplicateKey(rng);
    case 7:
      return editArray(rng);
    case 8:
      return deepNesting(rng);
    case 9:
    case 10:
      return crossIndex(rng);
    case 11:
      return rng.chance(0.5) ? cyclicChildren(rng) : nodeDag(rng);
    case 12:
      return badUri(rng);
    default:
      return farCamera(rng);
  }
}

}  // namespace chorus::fuzz
