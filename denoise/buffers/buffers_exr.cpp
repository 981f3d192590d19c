#include "denoise/buffers/buffers_exr.h"

#include <string>

#include "common/error.h"

namespace chorus {

namespace {

void appendSubBuffer(std::vector<ExrLayer>& layers, const SubBuffer& sub,
                     const std::string& prefix) {
  for (Quantity q : kAllQuantities) {
    const std::string name = std::string(quantityName(q));
    const bool defaultLayer = prefix.empty() && q == Quantity::Color;
    layers.push_back({defaultLayer ? "" : prefix + name, sub.get(q).mean});
    layers.push_back({prefix + name + "Variance", sub.get(q).varianceOfMean});
  }
  layers.push_back({prefix + "sampleCount", sub.sampleCount});
}

void appendSubBuffer(std::vector<ExrLayer>& layers, SubBuffer&& sub, const std::string& prefix) {
  for (Quantity q : kAllQuantities) {
    const std::string name = std::string(quantityName(q));
    const bool defaultLayer = prefix.empty() && q == Quantity::Color;
    layers.push_back({defaultLayer ? "" : prefix + name, std::move(sub.get(q).mean)});
    layers.push_back({prefix + name + "Variance", std::move(sub.get(q).varianceOfMean)});
  }
  layers.push_back({prefix + "sampleCount", std::move(sub.sampleCount)});
}

const Image& requireLayer(const std::vector<ExrLayer>& layers, const std::string& name,
                          int channels, const std::filesystem::path& file) {
  const ExrLayer* layer = findLayer(layers, name);
  if (!layer)
    throw fileError(file, "missing layer '" + (name.empty() ? "<default>" : name) +
                              "' (not a chorus render.exr?)");
  if (layer->image.channels() != channels)
    throw fileError(file, "layer '" + name + "' has " + std::to_string(layer->image.channels()) +
                              " channels, expected " + std::to_string(channels));
  return layer->image;
}

SubBuffer readSubBuffer(const std::vector<ExrLayer>& layers, const std::string& prefix,
                        const std::filesystem::path& file) {
  SubBuffer sub;
  for (Quantity q : kAllQuantities) {
    const std::string name = std::string(quantityName(q));
    const bool defaultLayer = prefix.empty() && q == Quantity::Color;
    sub.get(q).mean =
        requireLayer(layers, defaultLayer ? "" : prefix + name, channelCount(q), file);
    sub.get(q).varianceOfMean =
        requireLayer(layers, prefix + name + "Variance", channelCount(q), file);
  }
  sub.sampleCount = requireLayer(layers, prefix + "sampleCount", 1, file);
  return sub;
}

}  // namespace

std::vector<ExrLayer> sampleBuffersToLayers(const SampleBuffers& buffers) {
  std::vector<ExrLayer> layers;
  appendSubBuffer(layers, buffers.part(BufferPart::Full), "");
  if (buffers.splitCount() > 1)
    for (int k = 0; k < buffers.splitCount(); ++k)
      appendSubBuffer(layers, buffers.sub(k), "sub" + std::to_string(k) + ".");
  return layers;
}

std::vector<ExrLayer> sampleBuffersToLayers(SampleBuffers&& buffers) {
  std::vector<ExrLayer> layers;
  appendSubBuffer(layers, buffers.part(BufferPart::Full), "");
  if (buffers.splitCount() > 1)
    for (int k = 0; k < buffers.splitCount(); ++k)
      appendSubBuffer(layers, std::move(buffers.sub(k)), "sub" + std::to_string(k) + ".");
  buffers = SampleBuffers();
  return layers;
}

SampleBuffers sampleBuffersFromLayers(const std::vector<ExrLayer>& layers,
                                      const std::filesystem::path& fileForErrors) {
  std::vector<SubBuffer> subs;
  for (int k = 0;; ++k) {
    const std::string prefix = "sub" + std::to_string(k) + ".";
    if (!findLayer(layers, prefix + "color")) break;
    subs.push_back(readSubBuffer(layers, prefix, fileForErrors));
  }
  if (subs.empty()) subs.push_back(readSubBuffer(layers, "", fileForErrors));
  for (const SubBuffer& s : subs)
    if (s.width() != subs[0].width() || s.height() != subs[0].height())
      throw fileError(fileForErrors, "sub-buffers differ in size");
  return SampleBuffers(std::move(subs));
}

}  // namespace chorus
