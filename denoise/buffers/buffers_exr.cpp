#include "denoise/buffers/buffers_exr.h"

#include <cmath>
#include <string>
#include <type_traits>
#include <utility>

#include "common/error.h"

namespace chorus {

namespace {

// The layer name of a plane of the buffer with this prefix ("" for K = 1, "sub<k>." else).
std::string layerName(const std::string& prefix, Quantity q, Plane p) {
  const std::string name = std::string(quantityName(q));
  if (p == Plane::Variance) return prefix + name + "Variance";
  // The unprefixed colour mean is the default layer, what viewers show first.
  return prefix.empty() && q == Quantity::Color ? "" : prefix + name;
}

// Appends the planes `sub` holds: copied from a const sub-buffer, moved out of a mutable one.
template <typename Sub>
void appendSubBuffer(std::vector<ExrLayer>& layers, Sub& sub, const std::string& prefix) {
  const auto take = [](auto& image) -> Image {
    if constexpr (std::is_const_v<Sub>)
      return image;
    else
      return std::move(image);
  };
  for (Quantity q : kAllQuantities) {
    auto& planes = sub.get(q);
    if (!planes.mean.empty())
      layers.push_back({layerName(prefix, q, Plane::Mean), take(planes.mean)});
    if (!planes.varianceOfMean.empty())
      layers.push_back({layerName(prefix, q, Plane::Variance), take(planes.varianceOfMean)});
  }
  layers.push_back({prefix + "sampleCount", take(sub.sampleCount)});
}

const Image* findPlane(const std::vector<ExrLayer>& layers, const std::string& name, int channels,
                       const std::filesystem::path& file) {
  const ExrLayer* layer = findLayer(layers, name);
  if (!layer) return nullptr;
  if (layer->image.channels() != channels)
    throw fileError(file, "layer '" + name + "' has " + std::to_string(layer->image.channels()) +
                              " channels, expected " + std::to_string(channels));
  return &layer->image;
}

const Image& requirePlane(const std::vector<ExrLayer>& layers, const std::string& name,
                          int channels, const std::filesystem::path& file) {
  const Image* image = findPlane(layers, name, channels, file);
  if (!image)
    throw fileError(file, "missing layer '" + (name.empty() ? "<default>" : name) +
                              "' (not a chorus render.exr?)");
  return *image;
}

// Throws naming `file` and `layer` unless every value of `image` is finite and ≥ 0: a negative
// or non-finite one (a corrupt or hand-edited file) is not `what`.
void requireNonNegative(const Image& image, const std::string& layer,
                        const std::filesystem::path& file, const std::string& what) {
  for (const float v : image.values())
    if (!(v >= 0.0f) || !std::isfinite(v))
      throw fileError(file, "layer '" + layer + "' holds " + std::to_string(v) + ", not " + what);
}

SubBuffer readSubBuffer(const std::vector<ExrLayer>& layers, const std::string& prefix,
                        const std::filesystem::path& file) {
  SubBuffer sub;
  for (Quantity q : kAllQuantities) {
    const std::string meanName = layerName(prefix, q, Plane::Mean);
    const std::string varianceName = layerName(prefix, q, Plane::Variance);
    const int channels = channelCount(q);
    MeanVariance& planes = sub.get(q);
    if (q == Quantity::Color) {
      planes.mean = requirePlane(layers, meanName, channels, file);
      planes.varianceOfMean = requirePlane(layers, varianceName, channels, file);
      continue;
    }
    if (const Image* mean = findPlane(layers, meanName, channels, file)) planes.mean = *mean;
    if (const Image* variance = findPlane(layers, varianceName, channels, file)) {
      if (planes.mean.empty())
        throw fileError(file, "layer '" + varianceName + "' without '" + meanName + "'");
      planes.varianceOfMean = *variance;
    }
  }
  sub.sampleCount = requirePlane(layers, prefix + "sampleCount", 1, file);
  // Counts weigh the sub-buffers when they are merged: a bad one would turn every merged mean
  // into nonsense.
  requireNonNegative(sub.sampleCount, prefix + "sampleCount", file, "a sample count");
  return sub;
}

}  // namespace

namespace {

// Both overloads: Buffers is const SampleBuffers (copied from) or SampleBuffers (its
// sub-buffers moved from).
template <typename Buffers>
std::vector<ExrLayer> toLayers(Buffers& buffers) {
  std::vector<ExrLayer> layers;
  if (buffers.splitCount() == 1 && buffers.emission().empty()) {
    appendSubBuffer(layers, buffers.sub(0), "");
    return layers;
  }
  layers.push_back({"", buffers.noisyColor()});
  if (!buffers.emission().empty()) layers.push_back({"emission", buffers.emission()});
  for (int k = 0; k < buffers.splitCount(); ++k)
    appendSubBuffer(layers, buffers.sub(k), "sub" + std::to_string(k) + ".");
  return layers;
}

}  // namespace

std::vector<ExrLayer> sampleBuffersToLayers(const SampleBuffers& buffers) {
  return toLayers(buffers);
}

std::vector<ExrLayer> sampleBuffersToLayers(SampleBuffers&& buffers) {
  std::vector<ExrLayer> layers = toLayers(buffers);
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
  for (const SubBuffer& s : subs) {
    if (s.width() != subs[0].width() || s.height() != subs[0].height())
      throw fileError(fileForErrors, "sub-buffers differ in size");
    if (s.planes() != subs[0].planes())
      throw fileError(fileForErrors, "sub-buffers hold different layers");
  }
  SampleBuffers buffers(std::move(subs));
  if (const Image* emission = findPlane(layers, "emission", 3, fileForErrors)) {
    if (emission->width() != buffers.width() || emission->height() != buffers.height())
      throw fileError(fileForErrors, "layer 'emission' differs in size from the sub-buffers");
    // Added to every output image: a bad value would reach all of them.
    requireNonNegative(*emission, "emission", fileForErrors, "an emitted radiance");
    buffers.setEmission(*emission);
  }
  return buffers;
}

}  // namespace chorus
