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

namespace {

// merge() of two parts over pixels [first, first + size), with the per-pixel terms merge()
// computed: the same arithmetic in the same order as its general loop (so the same bits),
// without that loop's per-element indirection and bookkeeping (a third of a 4-spp preview's
// merge time went to it).
void mergeTwo(const SubBuffer& a, const SubBuffer& b, size_t first, size_t size,
              const std::vector<double>& weight, const std::vector<double>& samples,
              const std::vector<double>& varianceScale, SubBuffer& out) {
  for (Quantity q : kAllQuantities) {
    const size_t channels = size_t(channelCount(q));
    const float *meanA = a.get(q).mean.data(), *meanB = b.get(q).mean.data();
    const float *varianceA = a.get(q).varianceOfMean.data(),
                *varianceB = b.get(q).varianceOfMean.data();
    float* outMean = out.get(q).mean.data();
    float* outVariance = out.get(q).varianceOfMean.data();
    for (size_t i = 0; i < size; ++i) {
      const double wA = weight[2 * i], wB = weight[2 * i + 1];
      const double nA = samples[2 * i], nB = samples[2 * i + 1];
      const bool hasA = wA > 0, hasB = wB > 0;
      for (size_t e = (first + i) * channels; e < (first + i + 1) * channels; ++e) {
        const double mA = hasA ? double(meanA[e]) : 0.0, mB = hasB ? double(meanB[e]) : 0.0;
        double mean = 0;
        mean += wA * mA;
        mean += wB * mB;
        double m2 = 0;
        if (hasA) {
          const double delta = mA - mean;
          m2 += (double(varianceA[e]) * (nA - 1) + delta * delta) * nA;
        }
        if (hasB) {
          const double delta = mB - mean;
          m2 += (double(varianceB[e]) * (nB - 1) + delta * delta) * nB;
        }
        outMean[e] = float(mean);
        outVariance[e] = float(m2 * varianceScale[i]);
      }
    }
  }
}

}  // namespace

SubBuffer merge(const std::vector<const SubBuffer*>& parts) {
  if (parts.empty()) throw std::invalid_argument("merge: no sub-buffers");
  const int w = parts[0]->width(), h = parts[0]->height();
  for (const SubBuffer* p : parts)
    if (p->width() != w || p->height() != h)
      throw std::invalid_argument("merge: sub-buffers differ in size");
  if (parts.size() == 1) return *parts[0];

  SubBuffer out = SubBuffer::zeros(w, h);
  const size_t pixels = size_t(w) * size_t(h);
  const size_t count = parts.size();
  // Direct form of the merge: mean = Σ n_k mean_k / N, M2 = Σ (M2_k + n_k (mean_k − mean)²),
  // with every division per pixel rather than per channel. In parallel over blocks of pixels:
  // the merges behind a render's A, B and full inputs were a tenth of a 4-spp preview.
  tbb::parallel_for(tbb::blocked_range<size_t>(0, pixels, 16384), [&](const auto& block) {
    const size_t first = block.begin(), size = block.size();
    // Per pixel of the block: each part's weight n_k / N, its n_k, and 1 / (N (N − 1)).
    std::vector<double> weight(size * count), samples(size * count), varianceScale(size);
    for (size_t i = 0; i < size; ++i) {
      double n = 0;
      for (size_t k = 0; k < count; ++k) {
        const float nk = parts[k]->sampleCount.data()[first + i];
        samples[i * count + k] = nk > 0 ? nk : 0.0;  // parts without samples add nothing
        n += samples[i * count + k];
      }
      out.sampleCount.data()[first + i] = float(n);
      for (size_t k = 0; k < count; ++k)
        weight[i * count + k] = n > 0 ? samples[i * count + k] / n : 0.0;
      varianceScale[i] = n >= 2 ? 1.0 / (n * (n - 1)) : 0.0;
    }
    if (count == 2) {  // the common case (K = 2 renders, the halves of K = 4): see mergeTwo
      mergeTwo(*parts[0], *parts[1], first, size, weight, samples, varianceScale, out);
      return;
    }
    std::vector<const float*> partMean(count), partVariance(count);
    std::vector<double> means(count);
    for (Quantity q : kAllQuantities) {
      const size_t channels = size_t(channelCount(q));
      for (size_t k = 0; k < count; ++k) {
        partMean[k] = parts[k]->get(q).mean.data();
        partVariance[k] = parts[k]->get(q).varianceOfMean.data();
      }
      float* outMean = out.get(q).mean.data();
      float* outVariance = out.get(q).varianceOfMean.data();
      for (size_t i = 0; i < size; ++i) {
        const double* w = &weight[i * count];
        const double* nk = &samples[i * count];
        for (size_t e = (first + i) * channels; e < (first + i + 1) * channels; ++e) {
          double mean = 0;
          for (size_t k = 0; k < count; ++k) {
            means[k] = w[k] > 0 ? double(partMean[k][e]) : 0.0;
            mean += w[k] * means[k];
          }
          double m2 = 0;  // M2_k = V_k n_k (n_k − 1), V_k the part's variance of the mean
          for (size_t k = 0; k < count; ++k) {
            if (!(w[k] > 0)) continue;
            const double delta = means[k] - mean;
            m2 += (double(partVariance[k][e]) * (nk[k] - 1) + delta * delta) * nk[k];
          }
          outMean[e] = float(mean);
          outVariance[e] = float(m2 * varianceScale[i]);
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
