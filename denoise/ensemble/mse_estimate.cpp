#include "denoise/ensemble/mse_estimate.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <span>
#include <utility>

#include "common/error.h"
#include "denoise/base/filters/box_filter.h"
#include "denoise/ensemble/weight_filter.h"
#include "denoise/metrics/metrics.h"

namespace chorus {
namespace {

// The consistency test's allowance beyond k·|y^A − y^B|/2, as a fraction of mean |x| + |ȳ|:
// where the halves agree closely the full run may still differ by its smaller noise.
constexpr double kConsistencyAllowance = 0.1;

// The outlier cap's unit is at least this percentile of the image's per-pixel traces (chosen on
// the corpus's tuning half among 0.75, 0.9, 0.95 and 0.99: docs/ensemble-quality.md).
constexpr double kCapPercentile = 0.95;
// The relative terms' percentile reads every this-many of the rows the other image-wide
// statistics read (typicalTrace).
constexpr int kRelativeTraceRowStep = 4;

// The window's colour term: guide differences within this fraction of the guide itself count as
// no edge (chosen on the corpus's tuning half among 0, 0.02, 0.05 and 0.1:
// docs/ensemble-quality.md).
constexpr double kWindowColorTolerance = 0.05;

// Rows per task of the image-wide mean of the per-pixel terms, and the most rows it reads.
constexpr int kPriorBandRows = 32;
constexpr int kPriorRows = 256;

// The trace of a packed symmetric n × n matrix on the tangent space {Σv = 0}: tr H − 1ᵀH1/n,
// the part of H the solve sees. entry(k) = the k-th packed entry.
// Over the bases of `mask` only (the sub-matrix the solve sees where the others are missing).
template <typename Entry>
double tangentTrace(int n, BaseMask mask, const Entry& entry) {
  double trace = 0, total = 0;
  int count = 0;
  for (int i = 0, k = 0; i < n; ++i) {
    const bool inI = (mask >> i) & 1u;
    count += inI;
    for (int j = i; j < n; ++j, ++k) {
      if (!inI || !((mask >> j) & 1u)) continue;
      const double v = entry(k);
      trace += i == j ? v : 0.0;
      total += i == j ? v : 2.0 * v;
    }
  }
  return count > 0 ? trace - total / count : 0.0;
}

bool finite3(const float* v) {
  return std::isfinite(v[0]) && std::isfinite(v[1]) && std::isfinite(v[2]);
}

// The window's tap spacing: dense up to radius 8, every third pixel beyond, over 3 × 3 box means
// of the terms (boxFilterPlane), so that the radius-15 window costs what a radius-5 one does
// (and, on the 256- and 512-px corpora, blends better than the dense radius-15 window:
// docs/ensemble-quality.md).
int windowStep(int radius) {
  return radius > 8 ? 3 : 1;
}

// Index of (i, j), i ≤ j, in the packed upper triangle of an n × n matrix.
int packed(int i, int j, int n) {
  return i * n - i * (i - 1) / 2 + (j - i);
}

// h[k] += share·f_i·f_j over the packed upper triangle (i ≤ j, k in packed order), with the
// count of bases known at compile time so that the sums stay in registers (the generic loop
// spilled them: a fifth of the per-pixel terms' time).
template <int N>
void addOuterProductOf(double* h, double share, const double* f) {
  int k = 0;
  for (int i = 0; i < N; ++i) {
    const double s = share * f[i];
    for (int j = i; j < N; ++j, ++k) h[k] += s * f[j];
  }
}

template <int... Ns>
void addOuterProductFor(double* h, double share, const double* f, int n,
                        std::integer_sequence<int, Ns...>) {
  ((n == Ns + 1 ? addOuterProductOf<Ns + 1>(h, share, f) : void()), ...);
}

void addOuterProduct(double* h, double share, const double* f, int n) {
  addOuterProductFor(h, share, f, n, std::make_integer_sequence<int, kMaxDenoisers>());
}

std::vector<float> finitePlanes(const Image& image) {
  const size_t pixels = image.pixelCount();
  std::vector<float> planes(pixels * 3);
  for (size_t p = 0; p < pixels; ++p)
    for (int c = 0; c < 3; ++c) {
      const float v = image.data()[p * 3 + size_t(c)];
      planes[size_t(c) * pixels + p] = std::isfinite(v) ? v : 0.0f;
    }
  return planes;
}

// Per value, the mean of the bases' full runs that are finite there (0 where none is).
Image meanOfFiniteRuns(std::span<const BaseOutputs* const> bases) {
  const Image& first = bases[0]->full;
  Image mean(first.width(), first.height(), first.channels());
  tbb::parallel_for(tbb::blocked_range<size_t>(0, mean.size()),
                    [&](const tbb::blocked_range<size_t>& range) {
                      for (size_t e = range.begin(); e < range.end(); ++e) {
                        double sum = 0;
                        int count = 0;
                        for (const BaseOutputs* base : bases) {
                          const float v = base->full.data()[e];
                          if (std::isfinite(v)) sum += v, ++count;
                        }
                        mean.data()[e] = count > 0 ? float(sum / count) : 0.0f;
                      }
                    });
  return mean;
}

}  // namespace

void MseRows::pixel(int x, int y, PixelMse& out) const {
  const int n = baseCount_;
  const size_t pixels = size_t(y1_ - y0_) * size_t(width_);
  const size_t p = index(x, y);
  out.groups = groups_;
  out.valid = valid_[p];
  for (int g = 0; g < groups_; ++g) {
    const float* plane = planes_.data() + size_t(g * (entries_ + 1)) * pixels + p;
    MseMatrix& h = out.h[size_t(g)];
    h.resize(n, n);
    int e = 0;
    for (int i = 0; i < n; ++i)
      for (int j = i; j < n; ++j, ++e) h(i, j) = h(j, i) = plane[size_t(e) * pixels] * unit_;
    out.constant[size_t(g)] = plane[size_t(entries_) * pixels] * unit_;
  }
}

double MseRows::diagonal(int x, int y, int group, int base) const {
  const size_t pixels = size_t(y1_ - y0_) * size_t(width_);
  const size_t plane = size_t(group * (entries_ + 1) + packed(base, base, baseCount_));
  return planes_[plane * pixels + index(x, y)] * unit_;
}

MseEstimator::MseEstimator(const EnsembleGuides& guides, std::span<const BaseOutputs* const> bases,
                           const MseOptions& options)
    : MseEstimator(guides, bases, options, nullptr) {}

MseEstimator MseEstimator::oracle(const EnsembleGuides& guides,
                                  std::span<const BaseOutputs* const> bases, const Image& reference,
                                  const MseOptions& options) {
  if (reference.width() != guides.width() || reference.height() != guides.height() ||
      reference.channels() != 3)
    throw Error("the reference is " + std::to_string(reference.width()) + "x" +
                std::to_string(reference.height()) + "x" + std::to_string(reference.channels()) +
                ", expected " + std::to_string(guides.width()) + "x" +
                std::to_string(guides.height()) + "x3");
  return MseEstimator(guides, bases, options, &reference);
}

MseEstimator::MseEstimator(const EnsembleGuides& guides, std::span<const BaseOutputs* const> bases,
                           const MseOptions& options, const Image* reference)
    : options_(options) {
  checkEnsembleInputs(guides, bases);
  if (options.windowRadius < 0) throw Error("the MSE window radius must be at least 0");
  if (!(options.outlierCap >= 0) || !std::isfinite(options.outlierCap))
    throw Error("the MSE outlier cap must be a finite number ≥ 0");
  if (!(options.consistency >= 0) || !std::isfinite(options.consistency))
    throw Error("the consistency tolerance must be a finite number ≥ 0");
  if (!(options.imagePrior >= 0) || !std::isfinite(options.imagePrior))
    throw Error("the image prior's weight must be a finite number ≥ 0");
  if (!(options.plausibility == 0 || options.plausibility >= 1) ||
      !std::isfinite(options.plausibility))
    throw Error("the plausibility factor must be 0 (off) or a finite number ≥ 1");
  if (!(options.noisyFallback == 0 || options.noisyFallback >= 1) ||
      !std::isfinite(options.noisyFallback))
    throw Error("the noisy fallback's factor must be 0 (off) or a finite number ≥ 1");
  if (!(options.memberFallback == 0 || options.memberFallback >= 1) ||
      !std::isfinite(options.memberFallback))
    throw Error("the member fallback's factor must be 0 (off) or a finite number ≥ 1");
  // Inputs without quarters (K = 2, an outputs directory) use the halves; bases without half
  // runs (the pipeline leaves them out for the quarters estimate) can only use the quarters.
  const bool halfRuns = bases[0]->hasHalfRuns();
  if (!halfRuns && !reference && options.estimate != MseEstimate::Quarters)
    throw Error(std::string("the ") + estimateName(options.estimate) +
                " estimate needs the members' half runs");
  const bool quarters = options.estimate != MseEstimate::Halves && !reference &&
                        guides.quarters.size() == 4 && bases[0]->heldOut.size() == 4;
  width_ = guides.width();
  height_ = guides.height();
  baseCount_ = int(bases.size());
  for (int i = 0; i < baseCount_; ++i) outFull_[size_t(i)] = bases[size_t(i)]->full.data();
  std::vector<Fold> halves(2), heldOut;
  halves[0].comparator = guides.colorB.data();
  halves[1].comparator = guides.colorA.data();
  for (int i = 0; i < baseCount_ && halfRuns; ++i) {
    halves[0].out[size_t(i)] = bases[size_t(i)]->a.data();
    halves[1].out[size_t(i)] = bases[size_t(i)]->b.data();
  }
  // A quarter that is 0 everywhere holds no samples (a render below 4 spp: sample i goes to
  // sub-buffer i mod 4): compared with it, every member's error term would be its output
  // squared. Such folds are left out while two or more remain (3 spp: the default job's blend
  // 0.990 / 0.989 of before, tuning / validation, docs/ensemble-quality.md "Below 4 spp").
  if (quarters) {
    for (size_t k : comparedFolds(guides.quarters)) {
      Fold fold;
      fold.comparator = guides.quarters[k].data();
      for (int i = 0; i < baseCount_; ++i)
        fold.out[size_t(i)] = bases[size_t(i)]->heldOut[k].data();
      heldOut.push_back(fold);
    }
  }
  folds_ = quarters ? heldOut : halves;
  if (options.estimate == MseEstimate::Extrapolated && quarters) {
    // e(s) = a + b/s at s = ½, ¾ and 1 of the samples: e(1) = 1.5 e(¾) − 0.5 e(½).
    primaryWeight_ = 1.5;
    secondaryFolds_ = halves;
    secondaryWeight_ = -0.5;
  }
  reference_ = reference ? reference->data() : nullptr;

  // Normalise the absolute form by the mean |x|², so that float planes hold O(1) values for
  // any magnitude (1e-30 … 1e30).
  double sum = 0;
  size_t count = 0;
  for (const Image* image : reference ? std::vector<const Image*>{reference}
                                      : std::vector<const Image*>{&guides.colorA, &guides.colorB})
    for (float v : image->values())
      if (std::isfinite(v)) sum += std::abs(double(v)), ++count;
  scale_ = count > 0 ? sum / double(count) : 1.0;
  if (!(scale_ > 0.0) || !std::isfinite(scale_ * scale_) || !std::isfinite(1.0 / (scale_ * scale_)))
    scale_ = 1.0;

  if (options.windowRadius > 0) {
    const float sigmaSpatial =
        options.windowSigmaSpatial > 0 ? options.windowSigmaSpatial : float(options.windowRadius);
    windowKernel_.radius = options.windowRadius;
    windowKernel_.step = windowStep(options.windowRadius);
    windowKernel_.kSpatial = 0.5f / (sigmaSpatial * sigmaSpatial);
    windowKernel_.kNormal = 0.5f / (options.windowSigmaNormal * options.windowSigmaNormal);
    windowKernel_.kAlbedo = 0.5f / (options.windowSigmaAlbedo * options.windowSigmaAlbedo);
    windowGuides_.width = width_;
    windowGuides_.height = height_;
    windowGuides_.normal = finitePlanes(guides.normal);
    windowGuides_.albedo = finitePlanes(guides.albedo);
    if (options.windowSigmaColor > 0 && !reference) {
      // The members' mean blend: smooth, so it shows shadow edges and caustics that the features
      // do not, without the noisy colour's correlation with the comparators; its differences in
      // units of the noisy halves' spread (the weight filter's guide, makeColorGuide), so that
      // only a step larger than a half's noise separates two pixels. Beside the noise, a
      // relative tolerance: smooth shading is not an edge however clean the render (without it
      // the windows shrink to single pixels as the noise vanishes).
      WeightFilterOptions guideOptions;
      guideOptions.relativeTolerance = kWindowColorTolerance;
      const ColorGuide color =
          makeColorGuide(meanOfFiniteRuns(bases), guides.colorA, guides.colorB, guideOptions);
      windowGuides_.color = finitePlanes(color.color);
      windowGuides_.variance = finitePlanes(color.variance);
      windowKernel_.kColor = 0.5f / (options.windowSigmaColor * options.windowSigmaColor);
    }
  }
  // Every pass over the image asks which bases are finite at a pixel (the masks, the terms with
  // their window's halo, the prior): once per pixel here instead of four times there.
  validity_.resize(size_t(width_) * size_t(height_));
  tbb::parallel_for(tbb::blocked_range<size_t>(0, validity_.size()),
                    [&](const tbb::blocked_range<size_t>& range) {
                      for (size_t p = range.begin(); p < range.end(); ++p)
                        validity_[p] = computeValidAt(p);
                    });
  if (options.outlierCap > 0 && !reference_) {
    capUnit_ = std::max(1.0, typicalTrace(objectiveEpsilon()));
    if (options.imagePrior > 0) priorCapUnit_ = std::max(1.0, typicalTrace(priorEpsilon()));
  }
  if (options.imagePrior > 0 && !reference_) imagePrior_ = imagePriorTerms();
}

int MseEstimator::sampleStride() const {
  // Every stride-th row: an image-wide statistic needs no more than kPriorRows rows of pixels
  // (images up to 2 × kPriorRows rows use all of theirs).
  return std::max(1, height_ / kPriorRows);
}

double MseEstimator::priorEpsilon() const {
  return 0.25 * scale_ * scale_;
}

double MseEstimator::typicalTrace(double relativeEpsilon) const {
  // The relative terms' percentile from every fourth of those rows: it is a second pass for
  // the prior (5 % of the combination step with every row), and 64 rows of pixels hold enough
  // traces for a 95th percentile.
  const int stride = sampleStride() * (relativeEpsilon < 0 ? 1 : kRelativeTraceRowStep);
  const int rows = (height_ + stride - 1) / stride;
  std::vector<std::vector<double>> perRow(static_cast<size_t>(rows));
  tbb::parallel_for(0, rows, [&](int row) {
    const size_t y = size_t(row) * size_t(stride);
    for (int x = 0; x < width_; ++x) {
      const size_t p = y * size_t(width_) + size_t(x);
      const BaseMask valid = validAt(p);
      if (valid == 0 || !comparatorsFinite(p)) continue;
      const double trace =
          relativeEpsilon < 0 ? absoluteTrace(p, valid) : relativeTrace(p, valid, relativeEpsilon);
      if (std::isfinite(trace)) perRow[size_t(row)].push_back(trace);
    }
  });
  std::vector<double> traces;
  for (const std::vector<double>& row : perRow) traces.insert(traces.end(), row.begin(), row.end());
  if (traces.empty()) return 0.0;
  const size_t k = std::min(traces.size() - 1, size_t(kCapPercentile * double(traces.size())));
  std::nth_element(traces.begin(), traces.begin() + std::ptrdiff_t(k), traces.end());
  return traces[k];
}

double MseEstimator::absoluteTrace(size_t p, BaseMask valid) const {
  const FoldTerms terms = foldTermsAt(p, valid);
  double trace = 0;
  for (int i = 0; i < baseCount_; ++i)
    if ((valid >> i) & 1u) trace += terms.mean(i);
  return trace / (scale_ * scale_);
}

double MseEstimator::relativeTrace(size_t p, BaseMask valid, double relativeEpsilon) const {
  double trace = 0;
  for (const Fold& fold : folds_)
    for (int c = 0; c < 3; ++c) {
      const size_t ec = p * 3 + size_t(c);
      const double weight = relativeWeight(fold, valid, ec, relativeEpsilon);
      for (int i = 0; i < baseCount_; ++i) {
        if (!((valid >> i) & 1u)) continue;
        const double d = double(fold.out[size_t(i)][ec]) - fold.comparator[ec];
        trace += weight * d * d / double(folds_.size());
      }
    }
  return trace;
}

void MseEstimator::addPriorRow(int y, std::vector<float>& planes, std::vector<double>& sum,
                               std::vector<size_t>& count) const {
  const int n = baseCount_, entries = this->entries();
  // Relative to μ_f² + (mean |x| / 2)², per fold: every region counts by its relative error, as
  // in relMSE, but with a knee that follows the image's brightness, not its unit.
  const std::vector<BaseMask> present = pixelTerms(y, y + 1, planes, priorEpsilon(), priorCapUnit_);
  const size_t pixels = present.size();
  for (size_t p = 0; p < pixels; ++p) {
    const BaseMask mask = present[p];
    if (mask == 0) continue;
    for (int i = 0, k = 0; i < n; ++i)
      for (int j = i; j < n; ++j, ++k) {
        if (!((mask >> i) & 1u) || !((mask >> j) & 1u)) continue;
        ++count[size_t(k)];
        for (int g = 0; g < groups(); ++g)
          sum[size_t(g * (entries + 1) + k)] += planes[size_t(g * (entries + 1) + k) * pixels + p];
      }
  }
}

std::vector<double> MseEstimator::imagePriorTerms() const {
  // Bands in parallel, summed in band order (the same result for any thread count). Each entry
  // is the mean over the pixels where its bases are both present (a base missing over a region
  // changes nothing in the other bases' entries).
  // Every stride-th row (sampleStride): this pass over the whole image was half the cost of the
  // per-pixel terms.
  const int stride = sampleStride();
  const int rows = (height_ + stride - 1) / stride;
  const int bands = (rows + kPriorBandRows - 1) / kPriorBandRows;
  const int entries = this->entries();
  std::vector<std::vector<double>> sums(static_cast<size_t>(bands));
  std::vector<std::vector<size_t>> counts(static_cast<size_t>(bands));
  tbb::parallel_for(0, bands, [&](int band) {
    std::vector<double>& sum = sums[size_t(band)];
    std::vector<size_t>& count = counts[size_t(band)];
    sum.assign(size_t(planeCount()), 0.0);
    count.assign(size_t(entries + 1), 0);
    const int first = band * kPriorBandRows, last = std::min(rows, first + kPriorBandRows);
    std::vector<float> planes;
    for (int row = first; row < last; ++row) addPriorRow(row * stride, planes, sum, count);
  });
  std::vector<double> mean(size_t(planeCount()), 0.0);
  std::vector<size_t> count(size_t(entries + 1), 0);
  for (int band = 0; band < bands; ++band) {
    for (int k = 0; k < entries; ++k) count[size_t(k)] += counts[size_t(band)][size_t(k)];
    for (int k = 0; k < planeCount(); ++k) mean[size_t(k)] += sums[size_t(band)][size_t(k)];
  }
  bool any = false;
  for (int g = 0; g < groups(); ++g)
    for (int k = 0; k < entries; ++k) {
      double& v = mean[size_t(g * (entries + 1) + k)];
      v = count[size_t(k)] > 0 ? v / double(count[size_t(k)]) : 0.0;
      any = any || count[size_t(k)] > 0;
    }
  if (!any) return {};
  return mean;
}

void MseEstimator::addImagePrior(MseRows& rows) const {
  if (imagePrior_.empty()) return;
  const int n = baseCount_, entries = this->entries();
  const size_t pixels = size_t(rows.y1_ - rows.y0_) * size_t(width_);
  for (size_t p = 0; p < pixels; ++p) {
    // Both traces over the bases present at the pixel: the prior and the local evidence are
    // compared on the sub-matrix the solve sees there.
    const BaseMask mask = validAt(size_t(rows.y0_) * size_t(width_) + p);
    for (int g = 0; g < groups(); ++g) {
      const double* prior = imagePrior_.data() + size_t(g * (entries + 1));
      const double priorTrace = tangentTrace(n, mask, [&](int k) { return prior[k]; });
      if (!(priorTrace > 0)) continue;
      float* h = rows.planes_.data() + size_t(g * (entries + 1)) * pixels + p;
      const double local =
          tangentTrace(n, mask, [&](int k) { return double(h[size_t(k) * pixels]); });
      // No local evidence (no pixel with these bases in the window): the prior alone.
      const double factor = (local > 0 ? options_.imagePrior * local : 1.0) / priorTrace;
      for (int k = 0; k < entries; ++k) h[size_t(k) * pixels] += float(factor * prior[k]);
    }
  }
}

double MseEstimator::objectiveEpsilon() const {
  return options_.relative ? kRelMseEpsilon : -1.0;
}

BaseMask MseEstimator::validAt(size_t pixel) const {
  return validity_[pixel];
}

BaseMask MseEstimator::computeValidAt(size_t pixel) const {
  BaseMask mask = 0;
  const size_t e = pixel * 3;
  for (int i = 0; i < baseCount_; ++i) {
    bool finite = finite3(outFull_[size_t(i)] + e);
    if (!reference_)
      for (const Fold& fold : folds_) finite = finite && finite3(fold.out[size_t(i)] + e);
    if (finite) mask |= BaseMask(1) << i;
  }
  return mask;
}

BaseMask MseEstimator::solvableAt(size_t pixel) const {
  return masksAt(pixel).solvable;
}

bool MseEstimator::noBasePlausible(size_t pixel) const {
  return masksAt(pixel).noisyFallback;
}

MseEstimator::PixelMasks MseEstimator::masksAt(size_t pixel) const {
  const BaseMask valid = validAt(pixel);
  PixelMasks masks{valid, false};
  if (reference_) return masks;
  BaseMask kept = options_.consistency > 0 ? consistentBases(pixel, valid) : valid;
  if (kept == 0) kept = valid;
  masks.solvable = kept;
  if (!(options_.plausibility > 0 || options_.noisyFallback > 0) || valid == 0 ||
      !comparatorsFinite(pixel))
    return masks;
  const FoldTerms terms = foldTermsAt(pixel, valid);
  if (options_.plausibility > 0) masks.solvable = plausibleBases(kept, terms);
  const double k2 = options_.noisyFallback * options_.noisyFallback;
  masks.noisyFallback = options_.noisyFallback > 0 &&
                        terms.least(valid, baseCount_).mean > k2 * (terms.noise + terms.floorMean);
  return masks;
}

std::vector<int> MseEstimator::memberFallbacks(std::span<const Image> weights) const {
  const size_t pixels = size_t(width_) * size_t(height_);
  std::vector<int> out(pixels, -1);
  if (!(options_.memberFallback > 0) || reference_) return out;
  const double k2 = options_.memberFallback * options_.memberFallback;
  const int channels = weights[0].channels();
  tbb::parallel_for(size_t(0), pixels, [&](size_t p) {
    const BaseMask valid = validAt(p);
    if (valid == 0 || !comparatorsFinite(p)) return;
    const FoldTerms terms = foldTermsAt(p, valid);
    double blendTerm = 0;
    for (const Fold& fold : folds_)
      for (int c = 0; c < 3; ++c) {
        const size_t ec = p * 3 + size_t(c);
        double z = 0;
        for (int i = 0; i < baseCount_; ++i) {
          const double w =
              weights[size_t(i)].data()[p * size_t(channels) + size_t(channels == 3 ? c : 0)];
          if (w != 0) z += w * fold.out[size_t(i)][ec];
        }
        blendTerm += (z - fold.comparator[ec]) * (z - fold.comparator[ec]);
      }
    blendTerm /= double(folds_.size());
    const double least = terms.least(valid, baseCount_).mean;
    if (!(blendTerm > k2 * (least + terms.noise + terms.floorMean))) return;
    for (int i = 0; i < baseCount_; ++i)
      if (((valid >> i) & 1u) && terms.mean(i) == least) {
        out[p] = i;
        break;
      }
  });
  return out;
}

BaseMask MseEstimator::consistentBases(size_t pixel, BaseMask mask) const {
  const size_t e = pixel * 3;
  BaseMask consistent = 0;
  for (int i = 0; i < baseCount_; ++i) {
    if (!((mask >> i) & 1u)) continue;
    bool close = true;
    for (int c = 0; c < 3; ++c) {
      // The mean of the fold runs and half their range (|y^A − y^B|/2 for the halves).
      double low = std::numeric_limits<double>::infinity(), high = -low, mean = 0;
      for (const Fold& fold : folds_) {
        const double v = fold.out[size_t(i)][e + size_t(c)];
        low = std::min(low, v), high = std::max(high, v), mean += v;
      }
      mean /= double(folds_.size());
      const double full = outFull_[size_t(i)][e + size_t(c)];
      close =
          close && std::abs(full - mean) <= options_.consistency * 0.5 * (high - low) +
                                                kConsistencyAllowance * (scale_ + std::abs(mean));
    }
    if (close) consistent |= BaseMask(1) << i;
  }
  return consistent;
}

bool MseEstimator::comparatorsFinite(size_t pixel) const {
  for (const Fold& fold : folds_)
    if (!finite3(fold.comparator + pixel * 3)) return false;
  return true;
}

double MseEstimator::comparatorNoise(size_t ec) const {
  return comparatorNoise(folds_, ec);
}

double MseEstimator::comparatorNoise(const std::vector<Fold>& folds, size_t ec) {
  // ((F − 1)/F)·(x_f − x̄_{−f})² is unbiased for Var(x_f) (equal variances): ½(x^A − x^B)² for
  // the halves.
  const double n = double(folds.size());
  double sum = 0, noise = 0;
  for (const Fold& fold : folds) sum += fold.comparator[ec];
  for (const Fold& fold : folds) {
    const double x = fold.comparator[ec], others = (sum - x) / (n - 1);
    noise += (n - 1) / n * (x - others) * (x - others);
  }
  return noise / n;
}

MseEstimator::FoldTerms MseEstimator::foldTermsAt(size_t pixel, BaseMask mask) const {
  const size_t e = pixel * 3;
  FoldTerms t;
  t.folds = int(folds_.size());
  for (size_t f = 0; f < folds_.size(); ++f) std::fill_n(t.t[f].begin(), baseCount_, 0.0);
  for (int c = 0; c < 3; ++c) {
    const size_t ec = e + size_t(c);
    double mean = 0;
    for (size_t f = 0; f < folds_.size(); ++f) {
      const double x = folds_[f].comparator[ec];
      const double floor = kConsistencyAllowance * (scale_ + std::abs(x));
      t.floor[f] += floor * floor;
      mean += x / double(folds_.size());
    }
    const double fMean = kConsistencyAllowance * (scale_ + std::abs(mean));
    t.floorMean += fMean * fMean;
    t.noise += comparatorNoise(ec);
  }
  for (int i = 0; i < baseCount_; ++i) {
    if (!((mask >> i) & 1u)) continue;
    for (size_t f = 0; f < folds_.size(); ++f)
      for (int c = 0; c < 3; ++c) {
        const size_t ec = e + size_t(c);
        const double d = double(folds_[f].out[size_t(i)][ec]) - folds_[f].comparator[ec];
        t.t[f][size_t(i)] += d * d;
      }
  }
  return t;
}

double MseEstimator::FoldTerms::mean(int i) const {
  double sum = 0;
  for (int f = 0; f < folds; ++f) sum += t[size_t(f)][size_t(i)];
  return sum / folds;
}

MseEstimator::FoldTerms::Least MseEstimator::FoldTerms::least(BaseMask mask, int baseCount) const {
  const double inf = std::numeric_limits<double>::infinity();
  Least l;
  l.fold.fill(inf);
  l.mean = inf;
  for (int i = 0; i < baseCount; ++i)
    if ((mask >> i) & 1u) {
      for (int f = 0; f < folds; ++f)
        l.fold[size_t(f)] = std::min(l.fold[size_t(f)], t[size_t(f)][size_t(i)]);
      l.mean = std::min(l.mean, mean(i));
    }
  return l;
}

BaseMask MseEstimator::plausibleBases(BaseMask mask, const FoldTerms& t) const {
  const FoldTerms::Least least = t.least(mask, baseCount_);
  // The whole-pixel test; the least d always passes (κ ≥ 1), so it never empties the mask.
  const double k2 = options_.plausibility * options_.plausibility;
  const double limit = k2 * (least.mean + t.noise + t.floorMean);
  BaseMask plausible = 0, inEveryFold = 0;
  for (int i = 0; i < baseCount_; ++i) {
    if (!((mask >> i) & 1u) || t.mean(i) > limit) continue;
    plausible |= BaseMask(1) << i;
    // Each fold's test, at 2κ: the term of a fold whose comparator is a firefly is useless, and
    // its size in the mean d hides the other folds' evidence.
    bool everyFold = true;
    for (int f = 0; f < t.folds; ++f)
      everyFold = everyFold && t.t[size_t(f)][size_t(i)] <=
                                   4.0 * k2 * (least.fold[size_t(f)] + t.floor[size_t(f)]);
    if (everyFold) inEveryFold |= BaseMask(1) << i;
  }
  // The fold tests may together reject every base (each fold's best fails another's test).
  return inEveryFold != 0 ? inEveryFold : plausible;
}

double MseEstimator::relativeWeight(const Fold& fold, BaseMask valid, size_t ec,
                                    double relativeEpsilon) const {
  double mu = 0;
  int count = 0;
  for (int i = 0; i < baseCount_; ++i)
    if ((valid >> i) & 1u) mu += fold.out[size_t(i)][ec], ++count;
  mu = count > 0 ? mu / count : 0.0;
  return 1.0 / (mu * mu + relativeEpsilon);
}

std::vector<BaseMask> MseEstimator::pixelTerms(int y0, int y1, std::vector<float>& planes,
                                               double relativeEpsilon, double capUnit) const {
  const bool relative = relativeEpsilon >= 0;
  const int n = baseCount_, entries = this->entries();
  const size_t pixels = size_t(y1 - y0) * size_t(width_);
  planes.assign(size_t(planeCount()) * pixels, 0.0f);
  std::vector<BaseMask> present(pixels, 0);
  std::array<double, 3 * ((kMaxDenoisers * (kMaxDenoisers + 1)) / 2 + 1)> acc{};
  std::array<double, kMaxDenoisers> first{};
  const double absoluteWeight = 1.0 / (scale_ * scale_);
  for (size_t local = 0; local < pixels; ++local) {
    const size_t q = size_t(y0) * size_t(width_) + local;
    const size_t e = q * 3;
    if (reference_ ? !finite3(reference_ + e) : !comparatorsFinite(q)) continue;
    const BaseMask valid = validAt(q);
    std::fill(acc.begin(), acc.begin() + planeCount(), 0.0);
    for (int c = 0; c < 3; ++c) {
      const size_t ec = e + size_t(c);
      double* h =
          acc.data() + size_t((options_.form == MseForm::PerChannel ? c : 0) * (entries + 1));
      if (reference_) {
        // The oracle: e = y − r, H += e eᵀ.
        const double r = reference_[ec];
        const double weight = relative ? 1.0 / (r * r + relativeEpsilon) : absoluteWeight;
        for (int i = 0; i < n; ++i)
          first[size_t(i)] = ((valid >> i) & 1u) ? double(outFull_[size_t(i)][ec]) - r : 0.0;
        addOuterProduct(h, weight, first.data(), n);
        continue;
      }
      // Per fold f, e_f = y^f − x_f (halves: e^A = y^A − x^B, e^B = y^B − x^A);
      // H += (1/F) Σ_f e_f e_fᵀ, c −= the comparators' estimated variance (½(x^A − x^B)²).
      // Extrapolated: 1.5 times the quarters' terms minus 0.5 times the halves'.
      const std::pair<const std::vector<Fold>*, double> groups[] = {
          {&folds_, primaryWeight_}, {&secondaryFolds_, secondaryWeight_}};
      // Relative terms divide each fold's terms by the square of that fold's own runs' mean:
      // a level that does not see the fold's comparator. The mean of the blended outputs
      // (every quarter's samples) did, and weighted a fold's terms down where its comparator's
      // noise was high, unevenly across the bases: at 4 spp it ranked bases as nearly equal
      // that the true relative error tells apart (docs/ensemble-quality.md).
      for (const auto& [folds, groupWeight] : groups) {
        if (folds->empty()) continue;
        double weightSum = 0;
        for (const Fold& fold : *folds) {
          const double weight =
              relative ? relativeWeight(fold, valid, ec, relativeEpsilon) : absoluteWeight;
          weightSum += weight;
          const double share = groupWeight * weight / double(folds->size());
          const double x = fold.comparator[ec];
          for (int i = 0; i < n; ++i)
            first[size_t(i)] = ((valid >> i) & 1u) ? double(fold.out[size_t(i)][ec]) - x : 0.0;
          addOuterProduct(h, share, first.data(), n);
        }
        h[entries] -= groupWeight * weightSum / double(folds->size()) * comparatorNoise(*folds, ec);
      }
    }
    if (options_.outlierCap > 0 && !reference_) {
      double trace = 0;
      for (int g = 0; g < groups(); ++g)
        for (int i = 0; i < n; ++i) trace += acc[size_t(g * (entries + 1) + packed(i, i, n))];
      const double factor = options_.outlierCap / (trace / capUnit + options_.outlierCap);
      for (int k = 0; k < planeCount(); ++k) acc[size_t(k)] *= factor;
    }
    bool finite = true;
    for (int k = 0; k < planeCount(); ++k) finite = finite && std::isfinite(float(acc[size_t(k)]));
    if (!finite) continue;
    for (int k = 0; k < planeCount(); ++k)
      planes[size_t(k) * pixels + local] = float(acc[size_t(k)]);
    present[local] = valid;
  }
  return present;
}

MseRows MseEstimator::rows(int y0, int y1) const {
  y0 = std::clamp(y0, 0, height_);
  y1 = std::clamp(y1, y0, height_);
  MseRows out;
  out.y0_ = y0;
  out.y1_ = y1;
  out.width_ = width_;
  out.baseCount_ = baseCount_;
  out.groups_ = groups();
  out.entries_ = entries();
  out.unit_ = options_.relative ? 1.0 : scale_ * scale_;
  const size_t pixels = size_t(y1 - y0) * size_t(width_);
  out.valid_.resize(pixels);
  out.fallback_.resize(pixels);
  for (size_t local = 0; local < pixels; ++local) {
    const PixelMasks masks = masksAt(size_t(y0) * size_t(width_) + local);
    out.valid_[local] = masks.solvable;
    out.fallback_[local] = masks.noisyFallback;
  }

  const int r = options_.windowRadius;
  if (r == 0) {
    pixelTerms(y0, y1, out.planes_, objectiveEpsilon(), capUnit_);
    addImagePrior(out);
    return out;
  }
  // Per-pixel terms of the rows the window reaches, then the joint-bilateral window. A pixel
  // where some bases are missing (non-finite) still adds the entries of the bases present;
  // where any is missing, presence planes (1 where base i is present, 1 where the pixel has
  // terms at all) are filtered alongside, and entry (i, j) is divided by the window's share of
  // pixels with both present: the window's mean over the pixels that have the entry (exact
  // where one base has holes, an approximation where several have different ones).
  // A sparse window's taps read box means (below): half a box more of halo.
  const int step = windowKernel_.step;
  const int halo = r + step / 2;
  const int inY0 = std::max(0, y0 - halo), inY1 = std::min(height_, y1 + halo);
  std::vector<float> in;
  const std::vector<BaseMask> present = pixelTerms(inY0, inY1, in, objectiveEpsilon(), capUnit_);
  const size_t inPixels = size_t(inY1 - inY0) * size_t(width_);
  const BaseMask all = allBases(baseCount_);
  const bool holes =
      std::any_of(present.begin(), present.end(), [&](BaseMask m) { return m != 0 && m != all; });
  const int presencePlanes = holes ? baseCount_ + 1 : 0;
  if (holes) {
    in.resize(size_t(planeCount() + presencePlanes) * inPixels, 0.0f);
    float* presence = in.data() + size_t(planeCount()) * inPixels;
    for (size_t local = 0; local < inPixels; ++local) {
      if (present[local] == 0) continue;
      presence[local] = 1.0f;
      for (int i = 0; i < baseCount_; ++i)
        if ((present[local] >> i) & 1u) presence[size_t(i + 1) * inPixels + local] = 1.0f;
    }
  }
  out.planes_.assign(size_t(planeCount()) * pixels, 0.0f);
  std::vector<float> outPresence(size_t(presencePlanes) * pixels);
  std::vector<const float*> inPlanes;
  std::vector<float*> outPlanes;
  for (int k = 0; k < planeCount() + presencePlanes; ++k) {
    inPlanes.push_back(in.data() + size_t(k) * inPixels);
    outPlanes.push_back(k < planeCount() ? out.planes_.data() + size_t(k) * pixels
                                         : outPresence.data() + size_t(k - planeCount()) * pixels);
  }
  if (step > 1) {
    // Taps every `step` pixels over step × step box means of the terms (in place): as many
    // pixels' terms as the dense window averages, at 1/step² of its taps.
    std::vector<float> scratch;
    for (int k = 0; k < planeCount() + presencePlanes; ++k)
      boxFilterPlane(in.data() + size_t(k) * inPixels, in.data() + size_t(k) * inPixels, width_,
                     inY1 - inY0, step / 2, scratch);
  }
  filterPlaneRows(windowGuides_, windowKernel_, inPlanes, inY0, y0, y1, outPlanes);
  if (holes) {
    const int n = baseCount_, entries = this->entries();
    for (size_t p = 0; p < pixels; ++p) {
      const float any = outPresence[p];
      for (int i = 0, k = 0; i < n; ++i)
        for (int j = i; j < n; ++j, ++k) {
          const float share = std::min(outPresence[size_t(i + 1) * pixels + p],
                                       outPresence[size_t(j + 1) * pixels + p]);
          for (int g = 0; g < groups(); ++g) {
            float& v = out.planes_[size_t(g * (entries + 1) + k) * pixels + p];
            v = share > 0 ? v * (any / share) : 0.0f;
          }
        }
    }
  }
  addImagePrior(out);
  return out;
}

PixelMse MseEstimator::at(int x, int y) const {
  PixelMse out;
  rows(y, y + 1).pixel(x, y, out);
  return out;
}

}  // namespace chorus
