#include "denoise/base/filters/collaborative_regression.h"

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <span>
#include <stdexcept>
#include <utility>
#include <vector>

#include "denoise/base/filters/bordered_planes.h"
#include "denoise/util/simd_clones.h"

// The kernels below are built for AVX-512F, AVX2 and the baseline (simd_clones.h). Contraction
// into FMA is off for all of this file, so that every build gives the same bits; the pragma
// comes after the includes, and every helper the kernels inline is defined below it (GCC does
// not inline across different optimisation options).
#pragma GCC optimize("fp-contract=off")
// Helpers pass 64-byte vectors by value, so every one is always_inline: an out-of-line copy is
// compiled for the baseline ISA, whose ABI passes such values differently from the AVX-512 clone
// that calls it (at -O0, where nothing else is inlined, that read through a null pointer:
// tests/fuzz/cli/sweep-nfor-at-O0).
#pragma GCC diagnostic ignored "-Wpsabi"

namespace chorus {
namespace {

// Centres are processed kLanes at a time, one per vector lane: the kLanes consecutive centres
// of a tile row share every window offset δ, so the weights w_δ(p), the neighbours' features
// and the data are contiguous vector loads and each lane's sums keep a fixed order (δ in raster
// order) whatever the vector width of the build.
constexpr int kTileSize = 32;  // tile side; tiles are always kTileSize wide (see TileResult)
constexpr int kLanes = 16;
static_assert(kTileSize % kLanes == 0);
using Lanes = float __attribute__((vector_size(kLanes * sizeof(float))));

// A vector V from, and to, memory of its element type T at any alignment: memory outside the
// kernels' own stack frames holds plain floats and doubles, because code built for the
// baseline aligns these vector types to less than the AVX-512 clones assume.
template <typename V, typename T>
[[gnu::always_inline]] inline V loadVector(const T* p) {
  V v;
  std::memcpy(&v, p, sizeof v);
  return v;
}

template <typename V, typename T>
[[gnu::always_inline]] inline void storeVector(T* p, V v) {
  std::memcpy(p, &v, sizeof v);
}

[[gnu::always_inline]] inline Lanes splat(float v) {
  return Lanes{} + v;
}

// The Gram sums are formed in double: on near-collinear columns (a smooth surface's normals
// are almost linear in dx, dy) the part of a column the others do not explain is far below
// float rounding of the sums, and a float Gram either loses it or (with a coarse pivot
// tolerance) has to drop the column — which Tungsten's QR on √W X keeps. The products of
// float inputs w · x_a are exact in double. They run over half a group's lanes at a time (one
// AVX-512 register per sum), so that a block of them stays in registers over a window row.
constexpr int kHalf = kLanes / 2;
using HalfSums = double __attribute__((vector_size(kHalf * sizeof(double))));
using SumLanes = double __attribute__((vector_size(kLanes * sizeof(double))));
[[gnu::always_inline]] inline SumLanes wide(Lanes v) {
  return __builtin_convertvector(v, SumLanes);
}
// Eight lanes (the AVX2 path's part of a group) and their values in double.
using EightLanes = float __attribute__((vector_size(8 * sizeof(float))));
[[gnu::always_inline]] inline HalfSums eightWide(EightLanes v) {
  return __builtin_convertvector(v, HalfSums);
}

// Columns of the design matrix and of the data: d ≤ kMaxGramSize, C ≤ kMaxGramRhs.
constexpr int kMaxColumns = kMaxGramSize + kMaxGramRhs;
// Sums per centre: the upper triangle of G (d × d) and B (d × C), row by row of G:
// G_a,a … G_a,d−1, B_a,0 … B_a,C−1.
constexpr int kMaxSums = kMaxGramSize * (kMaxGramSize + 1) / 2 + kMaxGramSize * kMaxGramRhs;

// The inputs of one tile row group: kLanes centres (x0 … x0 + kLanes − 1, y) and where to read.
struct Group {
  int x0, y;
  int r, d, channels;        // window radius, design columns, data channels
  const float* weights;      // w_δ(first centre) = weights[offsetIndex(δ) · weightStride]
  size_t weightStride;       // floats between the weight planes of consecutive offsets
  int power;                 // the regression's weights: the table's to this power (toPower)
  bool floorCentre;          // raised centre weights keep at least centreFloor
  float centreFloor;         // (CenterWeight::Computed) where the centre is inside the image:
  int insideLanes;           // in the first insideLanes lanes
  const BorderedPlanes* fu;  // features (m planes) then data (C planes), zero border ≥ r + kLanes
};

[[gnu::always_inline]] inline void centreFeatures(const Group& g, int d, Lanes* fp) {
  for (int j = 0; j < d - 3; ++j) fp[j] = loadVector<Lanes>(g.fu->row(j, g.y) + g.x0);
}

// exp(−41): fast_exp gives 0 below about this.
constexpr float kSmallestWeight = 1.6e-18f;

// The weights w of offset (dx, dy) raised to the group's power: w^p is the weight of the
// bandwidth k / √p, whose distances are p times larger (up to ε and the distance clamp, which
// only decide where weights are 0 anyway). Like computed weights, they are 0 where exp would
// underflow, and the centre weight keeps the floor of CenterWeight::Computed.
// V: the group's lanes [lane0, lane0 + width of V).
template <typename V>
[[gnu::always_inline]] inline V toPower(const Group& g, V w, int dx, int dy, int lane0) {
  constexpr int width = int(sizeof(V) / sizeof(float));
  V p = w;
  for (int e = 1; e < g.power; ++e) p *= w;
  p = p < (V{} + kSmallestWeight) ? V{} : p;
  if (dx == 0 && dy == 0 && g.floorCentre)
    for (int lane = 0; lane < width && lane < g.insideLanes - lane0; ++lane)
      p[lane] = p[lane] < g.centreFloor ? g.centreFloor : p[lane];
  return p;
}

inline const float* offsetWeights(const Group& g, int dx, int dy) {
  const int side = 2 * g.r + 1;
  return g.weights + size_t((dy + g.r) * side + (dx + g.r)) * g.weightStride;
}

// The kernels are written once for a shape known at compile time (kD design columns, kC data
// channels: loops fully unrolled, the design row in registers) or, with kD = kC = 0, read
// from the group at run time.
constexpr int kNforColumns = 11, kNforChannels = 3;  // NFOR: 8 features, RGB

// Index of the sum of columns a ≤ b in the layout of kMaxSums (total = d + C columns).
constexpr int sumIndex(int total, int a, int b) {
  return a * total - a * (a - 1) / 2 + (b - a);
}

// The values of one window offset for half a group's lanes, in double: the weights and the
// columns x_a of the design row and the data (x_2 = dy is not stored: see accumulateSumsOf).
struct OffsetColumns {
  double w[kHalf];
  double x[kMaxColumns][kHalf];
};

// How the Gram sums of a window row are blocked: Sub holds `width` of a half's lanes (one vector
// register), and each block sums kRows design rows a ≠ 2 against every column, its accumulators
// (up to kRows × 13 registers for NFOR) held in registers over the row. AVX-512 (32 registers):
// the whole half, two rows a block ({0, 1}, {3, 4}, {5, 6}, …). AVX2 (16 registers): a quarter
// of the group, one row a block ({0}, {1}, {3}, …), since 26 accumulators of two registers each
// spilled on every offset (5× slower). Every sum adds the same terms in the same order
// either way, so both give the same bits.
using QuarterSums = double __attribute__((vector_size(kHalf / 2 * sizeof(double))));
// (The vector types are declared here: GCC drops vector_size on a type that depends on a
// template parameter.)
template <typename SubSums, int kRows>
struct SumBlocks {
  using Sub = SubSums;
  static constexpr int width = int(sizeof(Sub) / sizeof(double)), rowsPerBlock = kRows;
  static constexpr int blocks(int d) { return kRows == 2 ? d / 2 : d - 1; }
  // The first design row of block k (the second, if any, is the next).
  static constexpr int firstRow(int k) {
    if (kRows == 2) return k == 0 ? 0 : 2 * k + 1;
    return k < 2 ? k : k + 1;
  }
};
using WideBlocks = SumBlocks<HalfSums, 2>;
using NarrowBlocks = SumBlocks<QuarterSums, 1>;

template <typename V>
[[gnu::always_inline]] inline void addTo(double* sum, V v) {
  storeVector(sum, loadVector<V>(sum) + v);
}

// The window row dy's part of the sums (a, b) with a in block k, for the lanes lane0 …
// lane0 + width − 1 of a half: the row's sum Σ_dx w · x_a · x_b over its `live` offsets (in
// order) for every b ≥ a, b ≠ 2 — a block of accumulators that stays in registers over the
// row, instead of every sum loaded and stored at every offset — is added to
// sums[sumIndex(a, b)]. Block 0 also adds the sums with the dy column (a or b = 2): dy times the
// row's sums with column 0.
template <typename Blocks>
[[gnu::always_inline]] inline void rowBlockSums(int d, int total, int k, const OffsetColumns* cols,
                                                int live, int dy, int lane0,
                                                double (*sums)[kHalf]) {
  using Sub = typename Blocks::Sub;
  constexpr int kRows = Blocks::rowsPerBlock;
  const int a0 = Blocks::firstRow(k), a1 = a0 + 1;  // two rows only in WideBlocks: a0 ≠ 1
  const int rows = kRows == 2 && a1 < d ? 2 : 1;
  const int rowOf[2] = {a0, a1};
  Sub acc[kRows][kMaxColumns];
#pragma GCC unroll 2
  for (int r = 0; r < rows; ++r)
#pragma GCC unroll 32
    for (int b = a0; b < total; ++b) acc[r][b] = Sub{};
  for (int i = 0; i < live; ++i) {
    const OffsetColumns& o = cols[i];
    Sub wa[kRows] = {};
#pragma GCC unroll 2
    for (int r = 0; r < rows; ++r)
      wa[r] = loadVector<Sub>(o.w + lane0) * loadVector<Sub>(o.x[rowOf[r]] + lane0);
#pragma GCC unroll 32
    for (int b = a0; b < total; ++b) {
      if (b == 2) continue;
      const Sub xb = loadVector<Sub>(o.x[b] + lane0);
#pragma GCC unroll 2
      for (int r = 0; r < rows; ++r)
        if (b >= rowOf[r]) acc[r][b] += wa[r] * xb;
    }
  }
#pragma GCC unroll 2
  for (int r = 0; r < rows; ++r)
#pragma GCC unroll 32
    for (int b = rowOf[r]; b < total; ++b)
      if (b != 2) addTo(sums[sumIndex(total, rowOf[r], b)] + lane0, acc[r][b]);
  if (k == 0) {
    const Sub rowDy = Sub{} + double(dy), withDy = rowDy * acc[0][0];
    addTo(sums[sumIndex(total, 0, 2)] + lane0, withDy);
    addTo(sums[sumIndex(total, 1, 2)] + lane0, rowDy * acc[0][1]);
    addTo(sums[sumIndex(total, 2, 2)] + lane0, rowDy * withDy);
#pragma GCC unroll 32
    for (int b = 3; b < total; ++b) addTo(sums[sumIndex(total, 2, b)] + lane0, rowDy * acc[0][b]);
  }
}

template <typename Blocks, int kD, int kC, int... kBlock>
[[gnu::always_inline]] inline void allRowBlockSums(std::integer_sequence<int, kBlock...>,
                                                   const OffsetColumns* cols, int live, int dy,
                                                   int lane0, double (*sums)[kHalf]) {
  (rowBlockSums<Blocks>(kD, kD + kC, kBlock, cols, live, dy, lane0, sums), ...);
}

// The Gram sums of a group, in double: half[h][e] holds sum e (see kMaxSums) of the lanes
// h · kHalf … h · kHalf + kHalf − 1.
struct GroupSums {
  double half[2][kMaxSums][kHalf];
};

// Scratch of accumulateSums: the columns of a window row's live offsets (2r + 1 per half of
// the lanes).
struct WindowRowScratch {
  std::vector<OffsetColumns> columns;
};

// A half's column of equal values, in quarter vectors: an 8-double splat built for AVX2 went
// through the stack in scalar stores, and the wide loads that followed stalled on them.
[[gnu::always_inline]] inline void fillColumn(double* x, double v) {
  for (int i = 0; i < kHalf; i += kHalf / 2) storeVector(x + i, QuarterSums{} + v);
}

// Stores the lanes of v as the two halves' columns.
[[gnu::always_inline]] inline void storeHalves(double* lo, double* hi, SumLanes v) {
  storeVector(lo, __builtin_shufflevector(v, v, 0, 1, 2, 3, 4, 5, 6, 7));
  storeVector(hi, __builtin_shufflevector(v, v, 8, 9, 10, 11, 12, 13, 14, 15));
}

// A weight of exactly 0 adds exactly 0 (the values it multiplies are finite), so offsets where
// every centre of the group has one are skipped — neighbours across a strong edge, outside the
// image. accumulateSums marks them (skip[offsetIndex(δ)]) for accumulatePredictions.
//
// sums = Σ_δ w_δ · x_a · x_b for every centre of the group, in double. Each window row is
// summed on its own first and then added (two-level summation). Column 2 is dy, constant along
// a window row, so its sums are dy times the row's sums with column 0 (Σ w dy x_b = dy Σ w x_b),
// formed once per row instead of at every offset. The weights are also copied to
// `groupWeights` (w_δ at offsetIndex(δ) · kLanes) for the predictions: the table's planes are
// far apart, and this way it is read only once.
template <typename Blocks, int kD, int kC>
[[gnu::always_inline]] inline void accumulateSumsOf(const Group& g, GroupSums& sums,
                                                    float* groupWeights, uint8_t* skip,
                                                    WindowRowScratch& scratch) {
  const int d = kD ? kD : g.d, C = kD ? kC : g.channels, total = d + C;
  const int count = d * (d + 1) / 2 + d * C, side = 2 * g.r + 1;
  Lanes fp[kMaxGramSize];
  centreFeatures(g, d, fp);
  // The same, read in parts by the AVX2 path. A local copy, not the plane itself: read there,
  // NFOR's AVX2 path was 9 % slower (the stores may alias the planes, not this array).
  float fpMemory[kMaxGramSize][kLanes];
  for (int j = 0; j < d - 3; ++j) storeVector(fpMemory[j], fp[j]);
  for (int h = 0; h < 2; ++h)
    for (int e = 0; e < count; ++e) storeVector(sums.half[h][e], HalfSums{});
  OffsetColumns* cols[2] = {scratch.columns.data(), scratch.columns.data() + side};
  for (int dy = -g.r; dy <= g.r; ++dy) {
    // Where the columns ≥ 3 of offset (0, dy) are (features, then data).
    const float* planes[kMaxColumns];
    for (int a = 3; a < total; ++a) planes[a] = g.fu->row(a - 3, g.y + dy) + g.x0;
    int live = 0;
    for (int dx = -g.r; dx <= g.r; ++dx) {
      // Each offset's weights are in another plane of the table, a cache line no hardware
      // prefetcher predicts: ask for the next window row's while this one is summed.
      if (dy < g.r) __builtin_prefetch(offsetWeights(g, dx, dy + 1));
      const float* table = offsetWeights(g, dx, dy);
      if constexpr (Blocks::rowsPerBlock == 2) {
        Lanes w = loadVector<Lanes>(table);
        if (g.power > 1) w = toPower(g, w, dx, dy, 0);
        storeVector(groupWeights, w);
      } else {
        // Eight lanes at a time (AVX2): sixteen-lane weights were assembled from four SSE
        // pieces through the stack and reloaded whole, a store-forwarding stall per offset.
        for (int lane0 = 0; lane0 < kLanes; lane0 += 8) {
          EightLanes w = loadVector<EightLanes>(table + lane0);
          if (g.power > 1) w = toPower(g, w, dx, dy, lane0);
          storeVector(groupWeights + lane0, w);
        }
      }
      // Every lane +0 (weights are never negative): the bits OR-ed.
      uint64_t bits[kLanes / 2];
      std::memcpy(bits, groupWeights, sizeof bits);
      const float* w = groupWeights;
      groupWeights += kLanes;
      *skip = ((bits[0] | bits[1]) | (bits[2] | bits[3]) | (bits[4] | bits[5]) |
               (bits[6] | bits[7])) == 0;
      if (*skip++) continue;
      OffsetColumns* part[2] = {&cols[0][live], &cols[1][live]};
      ++live;
      if constexpr (Blocks::rowsPerBlock == 2) {
        storeHalves(part[0]->w, part[1]->w, wide(loadVector<Lanes>(w)));
#pragma GCC unroll 32
        for (int j = 0; j < d - 3; ++j)
          storeHalves(part[0]->x[3 + j], part[1]->x[3 + j],
                      wide(loadVector<Lanes>(planes[3 + j] + dx) - fp[j]));
#pragma GCC unroll 8
        for (int c = 0; c < C; ++c)
          storeHalves(part[0]->x[d + c], part[1]->x[d + c],
                      wide(loadVector<Lanes>(planes[d + c] + dx)));
      } else {
        for (int h = 0; h < 2; ++h) {
          const int lane0 = h * kHalf;
          OffsetColumns& to = *part[h];
          storeVector(to.w, eightWide(loadVector<EightLanes>(w + lane0)));
#pragma GCC unroll 32
          for (int j = 0; j < d - 3; ++j)
            storeVector(to.x[3 + j], eightWide(loadVector<EightLanes>(planes[3 + j] + dx + lane0) -
                                               loadVector<EightLanes>(fpMemory[j] + lane0)));
#pragma GCC unroll 8
          for (int c = 0; c < C; ++c)
            storeVector(to.x[d + c], eightWide(loadVector<EightLanes>(planes[d + c] + dx + lane0)));
        }
      }
      for (OffsetColumns* to : part) {
        fillColumn(to->x[0], 1.0);
        fillColumn(to->x[1], double(float(dx)));
      }
    }
    if (live == 0) continue;  // the row would add 0 to every sum
    for (int h = 0; h < 2; ++h)
      for (int lane0 = 0; lane0 < kHalf; lane0 += Blocks::width) {
        if constexpr (kD > 0)
          allRowBlockSums<Blocks, kD, kC>(std::make_integer_sequence<int, Blocks::blocks(kD)>{},
                                          cols[h], live, dy, lane0, sums.half[h]);
        else
          for (int k = 0; k < Blocks::blocks(d); ++k)
            rowBlockSums<Blocks>(d, total, k, cols[h], live, dy, lane0, sums.half[h]);
      }
  }
}

template <typename Blocks>
[[gnu::always_inline]] inline void accumulateSumsIn(const Group& g, GroupSums& sums,
                                                    float* groupWeights, uint8_t* skip,
                                                    WindowRowScratch& scratch) {
  if (g.d == kNforColumns && g.channels == kNforChannels)
    accumulateSumsOf<Blocks, kNforColumns, kNforChannels>(g, sums, groupWeights, skip, scratch);
  else
    accumulateSumsOf<Blocks, 0, 0>(g, sums, groupWeights, skip, scratch);
}

CHORUS_SIMD_CLONES void accumulateSums(const Group& g, GroupSums& sums, float* groupWeights,
                                       uint8_t* skip, WindowRowScratch& scratch, bool wide) {
  if (wide)
    accumulateSumsIn<WideBlocks>(g, sums, groupWeights, skip, scratch);
  else
    accumulateSumsIn<NarrowBlocks>(g, sums, groupWeights, skip, scratch);
}

// acc_c(q) += w_δ(p) · x_qᵀ β_c(p) and wsum(q) += w_δ(p) for every q = p + δ of the group's
// windows. beta[a · C + c] holds β_a,c of every lane; acc has C planes then wsum, each
// `accWidth` wide, positioned so that the group's first centre is at accAt.
// V holds sixteen lanes (AVX-512) or eight (AVX2: with sixteen-lane vectors the centre
// features and the predictions took two registers each and spilled on every offset); the parts
// of a group take turns within each offset, so every accumulator (a pixel in the windows of
// several lanes) adds the same terms in the same order either way: both give the same bits.
template <int kD, int kC, typename V>
[[gnu::always_inline]] inline void accumulatePredictionsOf(const Group& g,
                                                           const float* groupWeights,
                                                           const uint8_t* skip, const Lanes* beta,
                                                           float* acc, size_t accWidth,
                                                           size_t accPlane, size_t accAt) {
  constexpr int width = int(sizeof(V) / sizeof(float));
  const int d = kD ? kD : g.d, C = kD ? kC : g.channels;
  const float* betas = reinterpret_cast<const float*>(beta);
  // The centre features, read back from memory per part rather than held in registers; a local
  // copy, which the accumulators' stores cannot alias (see accumulateSumsOf's fpMemory).
  float fp[kMaxGramSize][kLanes];
  for (int j = 0; j < d - 3; ++j) std::memcpy(fp[j], g.fu->row(j, g.y) + g.x0, sizeof fp[j]);
  // The design row's dx and dy columns counted up from −r (exact small integers, so the same
  // values as a splat of float(dx)): a sixteen-lane splat per offset went through sixteen
  // scalar stores on AVX2, a third of this function's time.
  const V one = V{} + 1.0f, first = V{} + float(-g.r);
  V dyColumn = first;
  for (int dy = -g.r; dy <= g.r; ++dy, dyColumn += one) {
    V dxColumn = first;
    for (int dx = -g.r; dx <= g.r; ++dx, dxColumn += one, groupWeights += kLanes) {
      if (*skip++) continue;
      float* at = acc + accAt + ptrdiff_t(dy) * ptrdiff_t(accWidth) + dx;
      for (int lane0 = 0; lane0 < kLanes; lane0 += width) {
        // p_c = x_qᵀ β_c with the design row x_q = [1, dx, dy, f_j(q) − f_j(p) …], column by
        // column (x_0 = 1) for every channel at once, so that only the C predictions are live
        // across the row; each p_c adds its terms in order of a, as the Gram sums did.
        V p[kMaxGramRhs];
#pragma GCC unroll 4
        for (int c = 0; c < C; ++c) p[c] = loadVector<V>(betas + c * kLanes + lane0);
#pragma GCC unroll 32
        for (int a = 1; a < d; ++a) {
          const V xa = a == 1   ? dxColumn
                       : a == 2 ? dyColumn
                                : loadVector<V>(g.fu->row(a - 3, g.y + dy) + g.x0 + dx + lane0) -
                                      loadVector<V>(fp[a - 3] + lane0);
#pragma GCC unroll 4
          for (int c = 0; c < C; ++c)
            p[c] += loadVector<V>(betas + (a * C + c) * kLanes + lane0) * xa;
        }
        const V w = loadVector<V>(groupWeights + lane0);
        for (int c = 0; c < C; ++c) {
          float* plane = at + size_t(c) * accPlane + lane0;
          storeVector(plane, loadVector<V>(plane) + w * p[c]);
        }
        float* wsum = at + size_t(C) * accPlane + lane0;
        storeVector(wsum, loadVector<V>(wsum) + w);
      }
    }
  }
}

template <typename V>
[[gnu::always_inline]] inline void accumulatePredictionsIn(const Group& g,
                                                           const float* groupWeights,
                                                           const uint8_t* skip, const Lanes* beta,
                                                           float* acc, size_t accWidth,
                                                           size_t accPlane, size_t accAt) {
  if (g.d == kNforColumns && g.channels == kNforChannels)
    accumulatePredictionsOf<kNforColumns, kNforChannels, V>(g, groupWeights, skip, beta, acc,
                                                            accWidth, accPlane, accAt);
  else
    accumulatePredictionsOf<0, 0, V>(g, groupWeights, skip, beta, acc, accWidth, accPlane, accAt);
}

// wide: all sixteen lanes at once (AVX-512), else eight at a time (as accumulateSums's blocks).
CHORUS_SIMD_CLONES void accumulatePredictions(const Group& g, const float* groupWeights,
                                              const uint8_t* skip, const Lanes* beta, float* acc,
                                              size_t accWidth, size_t accPlane, size_t accAt,
                                              bool wide) {
  if (wide)
    accumulatePredictionsIn<Lanes>(g, groupWeights, skip, beta, acc, accWidth, accPlane, accAt);
  else
    accumulatePredictionsIn<EightLanes>(g, groupWeights, skip, beta, acc, accWidth, accPlane,
                                        accAt);
}

// A tile: kTileSize columns starting at x0 (the last tile of a row may extend past the image:
// its outside centres have weight 0 everywhere), rows [y0, y1) inside the image.
struct TileResult {
  PixelRect extent;  // the tile grown by r: every pixel its windows touch (may leave the image)
  std::vector<float> acc;  // C planes of acc, then wsum, over extent
};

struct ThreadState {
  NlMeansScratch scratch;
  std::vector<float> table;  // weights [offset][tile pixel], tile rows kTileSize wide
  GroupSums sums;
  WindowRowScratch windowRow;
  std::vector<float> groupWeights;  // w_δ of one group, offset after offset
  std::vector<uint8_t> skip;        // per offset: every weight of the group is 0
};

class Regression {
 public:
  Regression(const Image& image, const Image& features, const NlMeansWeights& weights,
             std::span<const int> powers, const GramTolerances& tol, GramSumBlocking blocking)
      : wide_(blocking == GramSumBlocking::Wide ||
              (blocking == GramSumBlocking::ForThisCpu && cpuHasAvx512f())),
        weights_(weights),
        powers_(powers.begin(), powers.end()),
        tol_(tol),
        width_(image.width()),
        height_(image.height()),
        r_(weights.params().r),
        side_(2 * r_ + 1),
        channels_(image.channels()),
        m_(features.channels()),
        d_(3 + m_),
        fu_(width_, height_, m_ + channels_, r_ + kLanes) {
    for (int j = 0; j < m_; ++j) {
      fu_.set(j, features, j);
      for (int y = 0; y < height_; ++y) {
        float* row = fu_.mutableRow(j, y);
        for (int x = 0; x < width_; ++x)
          if (!std::isfinite(row[x])) row[x] = 0.0f;
      }
    }
    for (int c = 0; c < channels_; ++c) fu_.set(m_ + c, image, c);
  }

  // One output per power.
  std::vector<Image> run() {
    std::vector<PixelRect> tiles;
    for (int y = 0; y < height_; y += kTileSize)
      for (int x = 0; x < width_; x += kTileSize)
        tiles.push_back({x, y, x + kTileSize, std::min(height_, y + kTileSize)});
    std::vector<std::vector<TileResult>> results(powers_.size(),
                                                 std::vector<TileResult>(tiles.size()));
    tbb::enumerable_thread_specific<ThreadState> states;
    tbb::parallel_for(size_t(0), tiles.size(), [&](size_t t) {
      ThreadState& st = states.local();
      fillWeightTable(tiles[t], st);
      for (size_t i = 0; i < powers_.size(); ++i)
        regressTile(tiles[t], st, powers_[i], results[i][t]);
    });
    std::vector<Image> out;
    for (const auto& r : results) out.push_back(gather(tiles, r));
    return out;
  }

 private:
  int offsetIndex(int dx, int dy) const { return (dy + r_) * side_ + (dx + r_); }

  // Planes of the weight table are this far apart: a little more than the tile, so that the
  // (2r+1)² weights of one centre do not all fall into the same cache set.
  static size_t planeStride() { return size_t(kTileSize) * kTileSize + 16; }

  // Weights of every offset for every centre of the tile: plane offsetIndex(δ) holds w_δ(p).
  // Centres outside the image get weight 0 (also at δ = 0), so they contribute nothing.
  void fillWeightTable(const PixelRect& tile, ThreadState& st) const {
    const size_t stride = planeStride(), offsets = size_t(side_ * side_);
    st.table.resize(stride * offsets);
    float* table = st.table.data();
    float* center = table + size_t(offsetIndex(0, 0)) * stride;
    weights_.center(tile, st.scratch, center);
    for (int y = 0; y < tile.height(); ++y)
      for (int x = width_ - tile.x0; x < kTileSize; ++x) center[y * kTileSize + x] = 0.0f;
    weights_.forEachOffsetPair([&](int dx, int dy) {
      weights_.offsetPair(tile, dx, dy, st.scratch, table + size_t(offsetIndex(dx, dy)) * stride,
                          table + size_t(offsetIndex(-dx, -dy)) * stride);
    });
  }

  // The regression with the table's weights to `power` (accumulateSums raises them).
  void regressTile(const PixelRect& tile, ThreadState& st, int power, TileResult& out) const {
    out.extent = tile.grown(r_);
    const size_t accWidth = size_t(out.extent.width()), accPlane = size_t(out.extent.area());
    out.acc.assign(accPlane * size_t(channels_ + 1), 0.0f);
    st.groupWeights.resize(size_t(side_ * side_) * kLanes);
    st.skip.resize(size_t(side_ * side_));
    st.windowRow.columns.resize(2 * size_t(side_));
    for (int y = tile.y0; y < tile.y1; ++y)
      for (int x0 = tile.x0; x0 < std::min(tile.x1, width_); x0 += kLanes) {
        const Group g{
            .x0 = x0,
            .y = y,
            .r = r_,
            .d = d_,
            .channels = channels_,
            .weights = st.table.data() + size_t(y - tile.y0) * kTileSize + size_t(x0 - tile.x0),
            .weightStride = planeStride(),
            .power = power,
            .floorCentre = weights_.params().center == CenterWeight::Computed,
            .centreFloor = weights_.params().minCenterWeight,
            .insideLanes = std::min(kLanes, width_ - x0),
            .fu = &fu_};
        accumulateSums(g, st.sums, st.groupWeights.data(), st.skip.data(), st.windowRow, wide_);
        // Declared in baseline code, where alignof(Lanes) is only 16, and read by the AVX-512
        // clone of accumulatePredictions, which may assume the type's full 64 bytes.
        alignas(64) Lanes beta[kMaxGramSize * kMaxGramRhs];
        solveLanes(st.sums, std::min(kLanes, width_ - x0), beta);
        const size_t at = size_t(y - out.extent.y0) * accWidth + size_t(x0 - out.extent.x0);
        accumulatePredictions(g, st.groupWeights.data(), st.skip.data(), beta, out.acc.data(),
                              accWidth, accPlane, at, wide_);
      }
  }

  // β of every live lane from its sums (rank-revealing, in double); β = 0 for the others.
  void solveLanes(const GroupSums& sums, int live, Lanes* beta) const {
    for (int e = 0; e < d_ * channels_; ++e) beta[e] = Lanes{};
    for (int lane = 0; lane < live; ++lane) {
      double gram[kMaxGramSize * kMaxGramSize], rhs[kMaxGramSize * kMaxGramRhs];
      const double(*s)[kHalf] = sums.half[lane / kHalf];
      const int at = lane % kHalf;
      for (int a = 0; a < d_; ++a) {
        for (int b = a; b < d_; ++b) gram[a * d_ + b] = (*s++)[at];
        for (int c = 0; c < channels_; ++c) rhs[a * channels_ + c] = (*s++)[at];
      }
      double solution[kMaxGramSize * kMaxGramRhs];
      solveGramPivoted(gram, rhs, d_, channels_, solution, tol_);
      for (int e = 0; e < d_ * channels_; ++e) beta[e][lane] = float(solution[e]);
    }
  }

  // out(q) = Σ_tiles acc / Σ_tiles wsum, tiles summed in index order for every pixel.
  Image gather(const std::vector<PixelRect>& tiles, const std::vector<TileResult>& results) const {
    Image result(width_, height_, channels_);
    const int bands = (height_ + kTileSize - 1) / kTileSize;
    tbb::parallel_for(0, bands, [&](int band) {
      const PixelRect rows{0, band * kTileSize, width_, std::min(height_, (band + 1) * kTileSize)};
      const size_t area = size_t(rows.area());
      std::vector<float> acc(area * size_t(channels_ + 1), 0.0f);  // C planes, then wsum
      for (size_t t = 0; t < tiles.size(); ++t) {
        const TileResult& tr = results[t];
        const PixelRect overlap = tr.extent.intersect(rows);
        const size_t trArea = size_t(tr.extent.area());
        for (int c = 0; c <= channels_; ++c)
          for (int y = overlap.y0; y < overlap.y1; ++y) {
            const float* src = tr.acc.data() + size_t(c) * trArea +
                               size_t(y - tr.extent.y0) * size_t(tr.extent.width()) +
                               size_t(overlap.x0 - tr.extent.x0);
            float* dst = acc.data() + size_t(c) * area + size_t(y - rows.y0) * size_t(width_) +
                         size_t(overlap.x0);
            for (int x = 0; x < overlap.width(); ++x) dst[x] += src[x];
          }
      }
      const float* wsum = acc.data() + size_t(channels_) * area;
      for (int y = rows.y0; y < rows.y1; ++y)
        for (int x = 0; x < width_; ++x) {
          const size_t i = size_t(y - rows.y0) * size_t(width_) + size_t(x);
          for (int c = 0; c < channels_; ++c)
            result(x, y, c) =
                wsum[i] > 0.0f ? acc[size_t(c) * area + i] / wsum[i] : fu_.row(m_ + c, y)[x];
        }
    });
    return result;
  }

  bool wide_;  // WideBlocks (AVX-512F: 32 registers of 8 doubles) or NarrowBlocks
  const NlMeansWeights& weights_;
  std::vector<int> powers_;
  GramTolerances tol_;
  int width_, height_, r_, side_, channels_, m_, d_;
  BorderedPlanes fu_;  // the features (non-finite → 0), then the data, with a zero border
};

}  // namespace

namespace {

void checkRegressionInputs(const Image& image, const Image& features,
                           const NlMeansWeights& weights) {
  if (weights.weightChannels() != 1)
    throw std::invalid_argument("collaborativeRegression: needs scalar weights");
  if (!image.sameSize(features) || image.width() != weights.width() ||
      image.height() != weights.height())
    throw std::invalid_argument("collaborativeRegression: image/feature/weight sizes differ");
  if (image.channels() > kMaxGramRhs || 3 + features.channels() > kMaxGramSize)
    throw std::invalid_argument("collaborativeRegression: too many channels or features");
}

}  // namespace

Image collaborativeRegression(const Image& image, const Image& features,
                              const NlMeansWeights& weights, const GramTolerances& tolerances,
                              GramSumBlocking blocking) {
  checkRegressionInputs(image, features, weights);
  const int one = 1;
  return Regression(image, features, weights, std::span<const int>(&one, 1), tolerances, blocking)
      .run()[0];
}

std::vector<Image> collaborativeRegressions(const Image& image, const Image& features,
                                            const NlMeansWeights& weights,
                                            std::span<const int> powers,
                                            const GramTolerances& tolerances,
                                            GramSumBlocking blocking) {
  for (int p : powers)
    if (p < 1 || p > kMaxWeightPower)
      throw std::invalid_argument("collaborativeRegressions: power out of range");
  checkRegressionInputs(image, features, weights);
  return Regression(image, features, weights, powers, tolerances, blocking).run();
}

}  // namespace chorus
