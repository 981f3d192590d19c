#include "tools/eval/cached_case.h"

#include <algorithm>
#include <sstream>

#include "common/atomic_file.h"
#include "common/error.h"
#include "common/image/exr_io.h"

namespace chorus {

namespace fs = std::filesystem;

namespace {

const char* const kGuideNames[] = {"color", "colorA", "colorB", "albedo", "normal"};

// "q0", "heldOut3": built by appending (GCC 12 warns falsely on "literal" + std::to_string).
std::string numbered(const char* prefix, size_t k) {
  std::string name = prefix;
  name += std::to_string(k);
  return name;
}

Image layer(const std::vector<ExrLayer>& layers, const std::string& name, const fs::path& file) {
  const ExrLayer* found = findLayer(layers, name);
  if (!found) throw fileError(file, "has no layer '" + name + "'");
  return found->image;
}

}  // namespace

fs::path cachedGuidesPath(const fs::path& dir) {
  return dir / "guides.exr";
}

fs::path cachedMemberPath(const fs::path& dir, const std::string& spec) {
  std::string name = spec;
  std::replace(name.begin(), name.end(), ':', '_');
  std::replace(name.begin(), name.end(), '=', '-');
  return dir / "members" / (name + ".exr");
}

void writeCachedGuides(const fs::path& dir, const EnsembleGuides& guides) {
  const Image* images[] = {&guides.color, &guides.colorA, &guides.colorB, &guides.albedo,
                           &guides.normal};
  std::vector<ExrLayer> layers;
  for (size_t i = 0; i < 5; ++i) layers.push_back({kGuideNames[i], *images[i]});
  for (size_t k = 0; k < guides.quarters.size(); ++k)
    layers.push_back({numbered("q", size_t(k)), guides.quarters[k]});
  ensureDirectory(dir);
  writeExr(cachedGuidesPath(dir), layers);
}

EnsembleGuides readCachedGuides(const fs::path& dir) {
  const fs::path file = cachedGuidesPath(dir);
  const std::vector<ExrLayer> layers = readExr(file);
  EnsembleGuides g;
  Image* images[] = {&g.color, &g.colorA, &g.colorB, &g.albedo, &g.normal};
  for (size_t i = 0; i < 5; ++i) *images[i] = layer(layers, kGuideNames[i], file);
  for (int k = 0; findLayer(layers, numbered("q", size_t(k))); ++k)
    g.quarters.push_back(layer(layers, numbered("q", size_t(k)), file));
  return g;
}

void writeCachedMember(const fs::path& dir, const BaseOutputs& outputs,
                       std::span<const double> seconds) {
  std::vector<ExrLayer> layers = {{"A", outputs.a}, {"B", outputs.b}, {"full", outputs.full}};
  for (size_t k = 0; k < outputs.heldOut.size(); ++k)
    layers.push_back({numbered("heldOut", size_t(k)), outputs.heldOut[k]});
  const fs::path file = cachedMemberPath(dir, outputs.name);
  ensureDirectory(file.parent_path());
  std::ostringstream times;
  for (size_t i = 0; i < seconds.size() && i < layers.size(); ++i)
    times << layers[i].name << "\t" << seconds[i] << "\n";
  writeTextAtomically(fs::path(file).replace_extension(".tsv"), times.str());
  writeExr(file, layers);  // last: marks the member cached
}

BaseOutputs readCachedMember(const fs::path& dir, const std::string& spec) {
  const fs::path file = cachedMemberPath(dir, spec);
  const std::vector<ExrLayer> layers = readExr(file);
  BaseOutputs o;
  o.name = spec;
  o.a = layer(layers, "A", file);
  o.b = layer(layers, "B", file);
  o.full = layer(layers, "full", file);
  for (int k = 0; findLayer(layers, numbered("heldOut", size_t(k))); ++k)
    o.heldOut.push_back(layer(layers, numbered("heldOut", size_t(k)), file));
  return o;
}

}  // namespace chorus
