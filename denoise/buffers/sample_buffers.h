#pragma once
// SampleBuffers: K statistically independent sub-buffers of the same pixels (K = 1, 2 or 4).
// Each sub-buffer holds, per pixel, the mean and the variance of the mean of colour and of every
// feature, plus its sample count. Denoisers never see SampleBuffers directly: they get a
// DenoiseInput (the buffer to denoise plus, when available, two independent halves of it).
#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "common/image/image.h"

namespace chorus {

// Mean and variance of the mean of one quantity, per pixel and channel.
// varianceOfMean = M2 / (n (n - 1)) over the n samples kept (0 when n < 2); NaN means "no
// sample of this quantity" (only possible in buffers read from other renderers).
struct MeanVariance {
  Image mean;
  Image varianceOfMean;
};

// The quantities a sub-buffer records. Channel counts: color, albedo, normal 3; depth,
// visibility 1.
enum class Quantity { Color, Albedo, Normal, Depth, Visibility };
inline constexpr std::array<Quantity, 5> kAllQuantities = {
    Quantity::Color, Quantity::Albedo, Quantity::Normal, Quantity::Depth, Quantity::Visibility};
int channelCount(Quantity q);
// "color", "albedo", "normal", "depth", "visibility" (the names used in files and on the CLI).
std::string_view quantityName(Quantity q);

// Which planes a sub-buffer holds: the mean and the variance of the mean of each quantity. Colour
// (mean and variance) is always held; a render for members that read fewer features records only
// what they read (a plane not held is an empty image), and a variance is held only with its mean.
enum class Plane { Mean, Variance };
class BufferPlanes {
 public:
  static BufferPlanes all();
  static BufferPlanes colorOnly();

  bool has(Quantity q, Plane p) const { return (bits_ & bit(q, p)) != 0; }
  // Adds a plane (a variance together with its mean).
  BufferPlanes with(Quantity q, Plane p) const;
  BufferPlanes operator|(BufferPlanes other) const { return fromBits(bits_ | other.bits_); }
  bool contains(BufferPlanes other) const { return (other.bits_ & ~bits_) == 0; }
  // The planes held here and not in `other` (for listing what is missing).
  BufferPlanes minus(BufferPlanes other) const { return fromBits(uint16_t(bits_ & ~other.bits_)); }
  bool operator==(const BufferPlanes&) const = default;
  // {"albedo", "normal variance", "visibility"}: the feature planes held (colour left out: it
  // is always held); list() joins them with ", ".
  std::vector<std::string> names() const;
  std::string list() const;

 private:
  static uint16_t bit(Quantity q, Plane p) {
    return uint16_t(1u << (2 * int(q) + (p == Plane::Variance ? 1 : 0)));
  }
  static BufferPlanes fromBits(uint16_t bits) {
    BufferPlanes planes;
    planes.bits_ = bits;
    return planes;
  }
  uint16_t bits_ = 0;
};

// One set of independent samples per pixel.
struct SubBuffer {
  MeanVariance color, albedo, normal, depth, visibility;
  Image sampleCount;  // 1 channel: samples accumulated per pixel (non-finite samples dropped)

  // An all-zero sub-buffer of the given size holding `planes` (the others empty).
  static SubBuffer zeros(int width, int height, BufferPlanes planes = BufferPlanes::all());

  int width() const { return color.mean.width(); }
  int height() const { return color.mean.height(); }
  MeanVariance& get(Quantity q);
  const MeanVariance& get(Quantity q) const;
  // The planes this sub-buffer holds (those that are not empty).
  BufferPlanes planes() const;
};

// The mean sample count over the pixels (0 when the buffer records none).
double meanSampleCount(const SubBuffer& buffer);
// Whether the buffer records sample counts and every one is 0: a sub-buffer of a render below K
// spp (sample i goes to sub-buffer i mod K).
bool holdsNoSamples(const SubBuffer& buffer);

// Exact merge of independent sub-buffers (Chan et al.'s parallel mean/M2 update, weighted by
// sample counts): the result equals accumulating all their samples into one buffer. The parts
// must hold the same planes; the result holds them too.
SubBuffer merge(const std::vector<const SubBuffer*>& parts);

// What a base denoiser runs on: the buffer to denoise and, when the source has them, two
// independent halves of exactly the same samples (whole = merge(halves)). Denoisers that need
// halves of their own input (NFOR, dual-buffer NL-means, RDFC) use `halves`.
struct DenoiseInput {
  SubBuffer whole;
  std::optional<std::array<SubBuffer, 2>> halves;
  // The share of the render's samples this input holds: 1 for the full buffer, 1/2 for a half,
  // 3/4 for a held-out input. The ensemble's partial runs stand in for the run on the full
  // buffer, so a rule that depends on how well a pixel is measured judges by the render's count
  // (guarded_denoiser.h's bound): a held-out run at 16 spp is bounded as the full run is.
  double sampleShare = 1.0;

  int width() const { return whole.width(); }
  int height() const { return whole.height(); }
};

// The mean sample count of the render a buffer comes from, given the share of the render's
// samples it holds (DenoiseInput::sampleShare); 0 without counts.
double renderSamplesPerPixel(const SubBuffer& buffer, double sampleShare);

// image += emission, channel for channel (nothing when emission is empty). Throws
// std::invalid_argument when the sizes differ.
void addEmission(Image& image, const Image& emission);

// Which part of a SampleBuffers an ensemble run denoises.
enum class BufferPart { HalfA, HalfB, Full };
std::string_view partName(BufferPart part);  // "A", "B", "full"

class SampleBuffers {
 public:
  SampleBuffers() = default;
  explicit SampleBuffers(std::vector<SubBuffer> subBuffers);

  int splitCount() const { return int(subBuffers_.size()); }
  int width() const { return subBuffers_.empty() ? 0 : subBuffers_[0].width(); }
  int height() const { return subBuffers_.empty() ? 0 : subBuffers_[0].height(); }
  const SubBuffer& sub(int k) const { return subBuffers_.at(size_t(k)); }
  SubBuffer& sub(int k) { return subBuffers_.at(size_t(k)); }
  const std::vector<SubBuffer>& subBuffers() const { return subBuffers_; }

  // Merge of the listed sub-buffers.
  SubBuffer merge(const std::vector<int>& indices) const;
  // Half A = first half of the sub-buffers, half B = second half, full = all of them.
  // Requires an even split count for the halves.
  SubBuffer part(BufferPart which) const;
  // The denoiser input for a part. With K = 4: half A gets quarters 0/1 as its halves, half B
  // quarters 2/3, full gets A/B. With K = 2 only the full buffer has halves; with K = 1 none.
  DenoiseInput input(BufferPart which) const;

  // The emission the camera sees directly or in mirrors (RGB), when the render
  // took it out of every sub-buffer's colour (renderer/render.h, separateEmission); else empty.
  // The sub-buffers' colour is then what is left to denoise, and every image of the scene is
  // that colour (or a denoised version of it) plus this plane: see noisyColor.
  const Image& emission() const { return emission_; }
  void setEmission(Image emission);
  // The full buffer's colour mean with the emission added back: the noisy image a user sees.
  Image noisyColor() const;

 private:
  std::vector<SubBuffer> subBuffers_;
  Image emission_;
};

}  // namespace chorus
