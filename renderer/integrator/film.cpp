#include "renderer/integrator/film.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace chorus::render {
namespace {

std::array<float, kPathSampleChannels> channels(const PathSample& s) {
  return {s.L.r,      s.L.g,      s.L.b,      s.albedo.r, s.albedo.g,  s.albedo.b,
          s.normal.x, s.normal.y, s.normal.z, s.depth,    s.visibility};
}

}  // namespace

bool PathSample::isFinite() const {
  // A sum of floats taken in double cannot overflow, so it is finite exactly when every term is
  // (one test instead of eleven). `emitted` needs none: it is the first of the non-negative
  // terms L sums, so it is finite when L is.
  double sum = 0;
  for (float v : channels(*this)) sum += double(v);
  return std::isfinite(sum);
}

bool PixelAccumulator::add(int k, const PathSample& sample) {
  if (!sample.isFinite()) return false;
  auto values = channels(sample);
  if (separateEmission_) {  // nothing of this on the hot path of a render that keeps emission in
    if (kept_++ == 0) firstEmitted_ = sample.emitted;
    for (int c = 0; c < 3; ++c) {
      const float e = sample.emitted[c];
      if (e != firstEmitted_[c]) emittedVaries_ = true;
      emittedSum_[size_t(c)] += double(e);
      values[size_t(c)] -= e;
    }
  }
  Stats& s = stats_[size_t(k)];
  ++s.count;
  const double rcpCount = 1.0 / double(s.count);  // one division for all channels
  for (size_t c = 0; c < values.size(); ++c) {
    // Welford: mean_n = mean_{n−1} + δ/n, M2_n = M2_{n−1} + δ (x − mean_n).
    const double x = values[c];
    const double delta = x - s.mean[c];
    s.mean[c] += delta * rcpCount;
    s.m2[c] += delta * (x - s.mean[c]);
  }
  return true;
}

Film::Film(int width, int height, int splits, BufferPlanes planes, bool separateEmission)
    : width_(width),
      height_(height),
      planes_(planes | BufferPlanes::colorOnly()),
      separateEmission_(separateEmission) {
  if (splits != 1 && splits != 2 && splits != 4)
    throw std::invalid_argument("Film: splits must be 1, 2 or 4");
  // Allocated and zeroed on as many threads as there are sub-buffers: the first touch of 24 MB
  // per sub-buffer at 512² was serial time in a 1-second preview.
  subBuffers_.resize(size_t(splits));
  tbb::parallel_for(
      0, splits, [&](int k) { subBuffers_[size_t(k)] = SubBuffer::zeros(width, height, planes_); });
  if (separateEmission) {
    emission_ = Image(width, height, 3);
    emittedVaries_.assign(size_t(width) * size_t(height), 0);
  }
}

void Film::store(int x, int y, const PixelAccumulator& pixel) {
  for (size_t k = 0; k < subBuffers_.size(); ++k) {
    const PixelAccumulator::Stats& s = pixel.stats(int(k));
    SubBuffer& sub = subBuffers_[k];
    const double n = s.count;
    size_t first = 0;  // the quantity's first channel in the accumulator, in kAllQuantities order
    for (Quantity q : kAllQuantities) {
      const int count = channelCount(q);
      MeanVariance& planes = sub.get(q);
      if (planes_.has(q, Plane::Mean)) {
        float* mean = planes.mean.pixel(x, y);
        for (int c = 0; c < count; ++c) mean[c] = float(s.mean[first + size_t(c)]);
      }
      if (planes_.has(q, Plane::Variance)) {
        float* variance = planes.varianceOfMean.pixel(x, y);
        for (int c = 0; c < count; ++c) {
          // Clamped so that a finite but huge sample cannot overflow the float output.
          const double v = n >= 2 ? s.m2[first + size_t(c)] / (n * (n - 1)) : 0.0;
          variance[c] = float(std::min(v, double(std::numeric_limits<float>::max())));
        }
      }
      first += size_t(count);
    }
    sub.sampleCount(x, y, 0) = float(s.count);
  }
  if (separateEmission_) {
    const Rgb e = pixel.emitted();
    float* out = emission_.pixel(x, y);
    out[0] = e.r, out[1] = e.g, out[2] = e.b;
    emittedVaries_[size_t(y) * size_t(width_) + size_t(x)] = pixel.emittedVaries() ? 1 : 0;
  }
}

double Film::samplesKept(int x, int y) const {
  double n = 0;
  for (const SubBuffer& sub : subBuffers_) n += sub.sampleCount(x, y, 0);
  return n;
}

Rgb PixelAccumulator::emitted() const {
  if (kept_ == 0) return Rgb(0.0f);
  return {float(emittedSum_[0] / kept_), float(emittedSum_[1] / kept_),
          float(emittedSum_[2] / kept_)};
}

SampleBuffers Film::release() {
  SampleBuffers buffers(std::move(subBuffers_));
  buffers.setEmission(std::move(emission_));
  emittedVaries_ = {};
  return buffers;
}

}  // namespace chorus::render
