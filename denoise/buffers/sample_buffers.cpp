#include "denoise/buffers/sample_buffers.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <stdexcept>
#include <vector>

namespace chorus {

int channelCount(Quantity q) {
  return (q == Quantity::Depth || q == Quantity::Visibility) ? 1 : 3;
}

std::string_view quantityName(Quantity q) {
  switch (q) {
    case Quantity::Color:
      return "color";
    case Quantity::Albedo:
      return "albedo";
    case Quantity::Normal:
      return "normal";
    case Quantity::Depth:
      return "depth";
    case Quantity::Visibility:
      return "visibility";
  }
  return "?";
}

std::string_view partName(BufferPart part) {
  switch (part) {
    case BufferPart::HalfA:
      return "A";
    case BufferPart::HalfB:
      return "B";
    case BufferPart::Full:
      return "full";
  }
  return "?";
}

SubBuffer SubBuffer::zeros(int width, int height) {
  SubBuffer s;
  for (Quantity q : kAllQuantities) {
    s.get(q).mean = Image(width, height, channelCount(q));
    s.get(q).varianceOfMean = Image(width, height, channelCount(q));
  }
  s.sampleCount = Image(width, height, 1);
  return s;
}

MeanVariance& SubBuffer::get(Quantity q) {
  switch (q) {
    case Quantity::Color:
      return color;
    case Quantity::Albedo:
      return albedo;
    case Quantity::Normal:
      return normal;
    case Quantity::Depth:
      return depth;
    case Quantity::Visibility:
      return visibility;
  }
  throw std::logic_error("SubBuffer::get: bad quantity");
}

const MeanVariance& SubBuffer::get(Quantity q) const {
  return const_cast<SubBuffer*>(this)->get(q);
}

SubBuffer merge(const std::vector<const SubBuffer*>& parts) {
  if (parts.empty()) throw std::invalid_argument("merge: no sub-buffers");
  const int w = parts[0]->width(), h = parts[0]->height();
  for (const SubBuffer* p : parts)
    if (p->width() != w || p->height() != h)
      throw std::invalid_argument("merge: sub-buffers differ in size");
  if (parts.size() == 1) return *parts[0];

  SubBuffer out = SubBuffer::zeros(w, h);
  const size_t pixels = size_t(w) * size_t(h);
  // In parallel over blocks of pixels, with each plane's pointers looked up once per block: the
  // merges behind a render's A, B and full inputs were a tenth of a 4-spp preview, serially.
  tbb::parallel_for(tbb::blocked_range<size_t>(0, pixels, 16384), [&](const auto& block) {
    for (size_t i = block.begin(); i < block.end(); ++i) {
      double n = 0;
      for (const SubBuffer* p : parts) n += p->sampleCount.data()[i];
      out.sampleCount.data()[i] = float(n);
    }
    std::vector<const float*> partMean(parts.size()), partVariance(parts.size());
    for (Quantity q : kAllQuantities) {
      const size_t channels = size_t(channelCount(q));
      for (size_t k = 0; k < parts.size(); ++k) {
        partMean[k] = parts[k]->get(q).mean.data();
        partVariance[k] = parts[k]->get(q).varianceOfMean.data();
      }
      float* outMean = out.get(q).mean.data();
      float* outVariance = out.get(q).varianceOfMean.data();
      for (size_t i = block.begin(); i < block.end(); ++i) {
        for (size_t e = i * channels; e < (i + 1) * channels; ++e) {
          // Chan et al.: combine (n, mean, M2) pairwise; M2 = V n (n - 1).
          double n = 0, mean = 0, m2 = 0;
          for (size_t k = 0; k < parts.size(); ++k) {
            const double nb = parts[k]->sampleCount.data()[i];
            if (nb <= 0) continue;
            const double meanB = partMean[k][e];
            const double m2B = double(partVariance[k][e]) * nb * (nb - 1);
            const double total = n + nb;
            const double delta = meanB - mean;
            mean += delta * nb / total;
            m2 += m2B + delta * delta * n * nb / total;
            n = total;
          }
          outMean[e] = float(mean);
          outVariance[e] = n >= 2 ? float(m2 / (n * (n - 1))) : 0.0f;
        }
      }
    }
  });
  return out;
}

SampleBuffers::SampleBuffers(std::vector<SubBuffer> subBuffers)
    : subBuffers_(std::move(subBuffers)) {
  for (const SubBuffer& s : subBuffers_)
    if (s.width() != width() || s.height() != height())
      throw std::invalid_argument("SampleBuffers: sub-buffers differ in size");
}

SubBuffer SampleBuffers::merge(const std::vector<int>& indices) const {
  std::vector<const SubBuffer*> parts;
  for (int k : indices) parts.push_back(&sub(k));
  return chorus::merge(parts);
}

namespace {
std::vector<int> range(int first, int count) {
  std::vector<int> r;
  for (int k = first; k < first + count; ++k) r.push_back(k);
  return r;
}
}  // namespace

SubBuffer SampleBuffers::part(BufferPart which) const {
  const int k = splitCount();
  if (which == BufferPart::Full) return merge(range(0, k));
  if (k % 2 != 0) throw std::logic_error("SampleBuffers: halves need an even split count");
  return merge(range(which == BufferPart::HalfA ? 0 : k / 2, k / 2));
}

DenoiseInput SampleBuffers::input(BufferPart which) const {
  const int k = splitCount();
  DenoiseInput in;
  in.whole = part(which);
  if (which == BufferPart::Full) {
    if (k >= 2 && k % 2 == 0)
      in.halves = std::array<SubBuffer, 2>{part(BufferPart::HalfA), part(BufferPart::HalfB)};
  } else if (k == 4) {
    const int first = which == BufferPart::HalfA ? 0 : 2;
    in.halves = std::array<SubBuffer, 2>{sub(first), sub(first + 1)};
  }
  return in;
}

}  // namespace chorus
