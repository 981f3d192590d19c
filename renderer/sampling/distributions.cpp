#include "renderer/sampling/distributions.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <string>

#include "common/error.h"

namespace chorus::render {

AliasTable::AliasTable(std::span<const float> weights) {
  const size_t n = weights.size();
  if (n == 0) throw Error("AliasTable: no weights");
  double total = 0;
  for (float w : weights) {
    if (!(w >= 0) || !std::isfinite(w)) throw Error("AliasTable: weights must be finite and >= 0");
    total += w;
  }
  if (!(total > 0)) throw Error("AliasTable: all weights are 0");

  pmf_.resize(n);
  probability_.assign(n, 1.0f);
  alias_.resize(n);
  for (size_t i = 0; i < n; ++i) alias_[i] = int(i);

  // Vose 1991: scale the probabilities by n so that the mean is 1, then pair each entry below 1
  // ("small") with one above ("large") that fills the rest of its column.
  std::vector<double> scaled(n);
  std::vector<int> small, large;
  for (size_t i = 0; i < n; ++i) {
    pmf_[i] = float(double(weights[i]) / total);
    scaled[i] = double(weights[i]) / total * double(n);
    (scaled[i] < 1.0 ? small : large).push_back(int(i));
  }
  while (!small.empty() && !large.empty()) {
    const int s = small.back(), l = large.back();
    small.pop_back();
    large.pop_back();
    probability_[size_t(s)] = float(scaled[size_t(s)]);
    alias_[size_t(s)] = l;
    scaled[size_t(l)] -= 1.0 - scaled[size_t(s)];
    (scaled[size_t(l)] < 1.0 ? small : large).push_back(l);
  }
  // Whatever remains is 1 up to rounding: such columns keep their own index.
  for (int i : small) probability_[size_t(i)] = 1.0f;
  for (int i : large) probability_[size_t(i)] = 1.0f;
}

int AliasTable::sample(float u, float* pmf, float* uRemapped) const {
  const int n = size();
  const float scaled = u * float(n);
  const int column = std::min(int(scaled), n - 1);
  const float frac = std::min(scaled - float(column), 0x1.fffffep-1f);
  const float p = probability_[size_t(column)];
  int index;
  float remapped;
  if (frac < p) {
    index = column;
    remapped = frac / p;
  } else {
    index = alias_[size_t(column)];
    remapped = (frac - p) / (1.0f - p);
  }
  if (pmf) *pmf = pmf_[size_t(index)];
  if (uRemapped) *uRemapped = std::min(remapped, 0x1.fffffep-1f);
  return index;
}

float AliasTable::pmf(int index) const {
  return index >= 0 && index < size() ? pmf_[size_t(index)] : 0.0f;
}

namespace {

// Normalised running sum of `func` (n values) into cdf[0..n]; returns the integral over [0,1]
// (the mean of func). An all-zero function gets a uniform cdf so that sampling stays defined.
float buildCdf(const float* func, int n, float* cdf) {
  double sum = 0;
  cdf[0] = 0;
  for (int i = 0; i < n; ++i) {
    sum += double(func[i]);
    cdf[i + 1] = float(sum);
  }
  if (sum > 0) {
    for (int i = 1; i <= n; ++i) cdf[i] = float(double(cdf[i]) / sum);
  } else {
    for (int i = 1; i <= n; ++i) cdf[i] = float(i) / float(n);
  }
  cdf[n] = 1.0f;
  return float(sum / n);
}

// Guide tables (Chen & Asau 1974): entry k of a cdf's guide is the interval that holds k / g,
// so the interval of u lies between entries ⌊u g⌋ and ⌊u g⌋ + 1 and the binary search runs only
// between them — the result of searching the whole cdf in a few probes of one or two cache lines
// (the searches over 1k-wide environment maps were 5 % of an environment-lit render).
int guideSize(int n) {
  return int(std::bit_ceil(unsigned(std::max(1, n / 16))));  // a power of two: ⌊u g⌋ is exact
}

int intervalOf(const float* cdf, int n, float u, int first, int last) {
  const float* upper = std::upper_bound(cdf + first + 1, cdf + last + 2, u);
  return std::clamp(int(upper - cdf) - 1, 0, n - 1);
}

// The guideSize(n) + 1 entries of a cdf's guide.
void buildGuide(const float* cdf, int n, int* guide) {
  const int g = guideSize(n);
  for (int k = 0; k <= g; ++k) guide[k] = intervalOf(cdf, n, float(k) / float(g), 0, n - 1);
}

// The interval i with cdf[i] <= u < cdf[i + 1] (skipping empty intervals) for u in [0, 1], and
// the position of u inside it as a fraction.
int findInterval(const float* cdf, int n, const int* guide, float u, float* offset) {
  const int g = guideSize(n);
  const int k = std::clamp(int(u * float(g)), 0, g - 1);
  const int i = intervalOf(cdf, n, u, guide[k], guide[k + 1]);
  const float width = cdf[i + 1] - cdf[i];
  *offset = width > 0 ? std::clamp((u - cdf[i]) / width, 0.0f, 0x1.fffffep-1f) : 0.0f;
  return i;
}

// (i + offset) / n, nudged down where rounding would carry it into cell i + 1, so that the
// point lies in the cell that was sampled and pdf() agrees with sample().
float positionInCell(int i, float offset, int n) {
  float x = (float(i) + offset) / float(n);
  while (x > 0 && int(x * float(n)) > i) x = std::nextafter(x, 0.0f);
  return x;
}

}  // namespace

PiecewiseConstant2D::PiecewiseConstant2D(std::span<const float> f, int nu, int nv)
    : nu_(nu), nv_(nv) {
  if (nu <= 0 || nv <= 0 || f.size() != size_t(nu) * size_t(nv))
    throw Error("PiecewiseConstant2D: expected " + std::to_string(nu) + " x " + std::to_string(nv) +
                " values");
  conditionalFunc_.resize(f.size());
  for (size_t i = 0; i < f.size(); ++i) {
    if (!(f[i] >= 0) || !std::isfinite(f[i]))
      throw Error("PiecewiseConstant2D: values must be finite and >= 0");
    conditionalFunc_[i] = f[i];
  }
  conditionalCdf_.resize(size_t(nv) * size_t(nu + 1));
  rowIntegral_.resize(size_t(nv));
  for (int v = 0; v < nv; ++v)
    rowIntegral_[size_t(v)] = buildCdf(&conditionalFunc_[size_t(v) * size_t(nu)], nu,
                                       &conditionalCdf_[size_t(v) * size_t(nu + 1)]);
  marginalCdf_.resize(size_t(nv + 1));
  integral_ = buildCdf(rowIntegral_.data(), nv, marginalCdf_.data());

  const size_t rowGuide = size_t(guideSize(nu)) + 1;
  conditionalGuide_.resize(size_t(nv) * rowGuide);
  for (int v = 0; v < nv; ++v)
    buildGuide(&conditionalCdf_[size_t(v) * size_t(nu + 1)], nu,
               &conditionalGuide_[size_t(v) * rowGuide]);
  marginalGuide_.resize(size_t(guideSize(nv)) + 1);
  buildGuide(marginalCdf_.data(), nv, marginalGuide_.data());
}

Vec2f PiecewiseConstant2D::sample(Vec2f u, float* pdf) const {
  float dv, du;
  const int v = findInterval(marginalCdf_.data(), nv_, marginalGuide_.data(), u.y, &dv);
  const int iu =
      findInterval(&conditionalCdf_[size_t(v) * size_t(nu_ + 1)], nu_,
                   &conditionalGuide_[size_t(v) * (size_t(guideSize(nu_)) + 1)], u.x, &du);
  if (pdf) {
    *pdf =
        integral_ > 0 ? conditionalFunc_[size_t(v) * size_t(nu_) + size_t(iu)] / integral_ : 1.0f;
  }
  return {positionInCell(iu, du, nu_), positionInCell(v, dv, nv_)};
}

float PiecewiseConstant2D::pdf(Vec2f p) const {
  if (nu_ == 0 || !(p.x >= 0 && p.x <= 1 && p.y >= 0 && p.y <= 1)) return 0;
  const int iu = std::clamp(int(p.x * float(nu_)), 0, nu_ - 1);
  const int v = std::clamp(int(p.y * float(nv_)), 0, nv_ - 1);
  // An all-zero function is sampled uniformly (density 1).
  if (!(integral_ > 0)) return 1.0f;
  return conditionalFunc_[size_t(v) * size_t(nu_) + size_t(iu)] / integral_;
}

}  // namespace chorus::render
