#include "renderer/sampling/sampler.h"

#include <array>

#if defined(__SSE4_1__)
#include <smmintrin.h>
#endif

namespace chorus::render {
namespace {

// 64-bit finaliser (the avalanche step of MurmurHash3): every input bit affects every output bit.
constexpr uint64_t mix64(uint64_t x) {
  x ^= x >> 33;
  x *= 0xff51afd7ed558ccdull;
  x ^= x >> 33;
  x *= 0xc4ceb9fe1a85ec53ull;
  x ^= x >> 33;
  return x;
}

constexpr uint64_t hashCombine(uint64_t h, uint64_t v) {
  return mix64(h ^ (v + 0x9e3779b97f4a7c15ull + (h << 6) + (h >> 2)));
}

constexpr uint32_t reverseBits(uint32_t x) {
  x = ((x >> 1) & 0x55555555u) | ((x & 0x55555555u) << 1);
  x = ((x >> 2) & 0x33333333u) | ((x & 0x33333333u) << 2);
  x = ((x >> 4) & 0x0f0f0f0fu) | ((x & 0x0f0f0f0fu) << 4);
  return __builtin_bswap32(x);  // the byte order: one instruction instead of two shift steps
}

// A seeded permutation of 32-bit words in which output bit k depends only on input bits 0..k
// (Laine & Karras 2011): additions, odd multiplications and x ^= x * even all have this
// property. Applied to bit-reversed values it flips each bit depending on all more significant
// bits, which is Owen's nested uniform scrambling (Burley 2020, §3). `Word` is uint32_t, or
// Lanes (four words side by side, permuted each with its own seed).
using Lanes = uint32_t __attribute__((vector_size(16)));
template <typename Word>
inline Word lowerBitsPermutation(Word x, Word seed) {
  x += seed;
  x ^= x * 0xf9b439fau;
  x *= (seed >> 16) | 1u;
  x ^= x * 0x91d93086u;
  x += seed * 0xa05f1119u;
  x ^= x * 0x8142c8eau;
  x ^= x * 0x3ceaaf36u;
  return x;
}

// Generator matrix columns of the second Sobol dimension (primitive polynomial x + 1):
// v_0 = 1/2, v_k = v_{k-1} xor (v_{k-1} / 2). The first dimension is the van der Corput
// sequence (the identity matrix), and together they form a (0,2)-sequence in base 2.
constexpr std::array<uint32_t, 32> makeSobolDimension1() {
  std::array<uint32_t, 32> v{};
  v[0] = 0x80000000u;
  for (int k = 1; k < 32; ++k) v[k] = v[k - 1] ^ (v[k - 1] >> 1);
  return v;
}

// The matrix-vector product over GF(2), a byte of the index at a time: entry [b][x] is the
// xor of the columns selected by the bits of x in byte b.
using SobolByteTable = std::array<std::array<uint32_t, 256>, 4>;
constexpr SobolByteTable makeSobolByteTable() {
  const std::array<uint32_t, 32> v = makeSobolDimension1();
  SobolByteTable table{};
  for (int b = 0; b < 4; ++b)
    for (int x = 0; x < 256; ++x)
      for (int k = 0; k < 8; ++k)
        if (x & (1 << k)) table[size_t(b)][size_t(x)] ^= v[size_t(8 * b + k)];
  return table;
}
constexpr SobolByteTable kSobolDimension1 = makeSobolByteTable();

// Owen scrambling of a binary fraction v is reverseBits(lowerBitsPermutation(reverseBits(v), s)).
// The draws below keep words bit-reversed between steps so that the reversals of successive
// scrambles and of the van der Corput sequence cancel: bit-identical to scrambling the textbook
// points, with 3 (get2D) and 2 (get1D) reversals instead of 7 and 5 (the sampler was a fifth of
// the render time).
//
// reverseBits(sobolDimension1(reverseBits(z))), a byte of z at a time: byte b of z is byte
// 3 − b of reverseBits(z), with its bits reversed.
constexpr SobolByteTable makeReversedSobolByteTable() {
  SobolByteTable table{};
  for (int b = 0; b < 4; ++b)
    for (uint32_t x = 0; x < 256; ++x)
      table[size_t(b)][x] = reverseBits(kSobolDimension1[size_t(3 - b)][reverseBits(x) >> 24]);
  return table;
}
constexpr SobolByteTable kReversedSobolDimension1 = makeReversedSobolByteTable();

inline uint32_t reversedSobolDimension1(uint32_t z) {
  return kReversedSobolDimension1[0][z & 0xffu] ^ kReversedSobolDimension1[1][(z >> 8) & 0xffu] ^
         kReversedSobolDimension1[2][(z >> 16) & 0xffu] ^ kReversedSobolDimension1[3][z >> 24];
}

// The top 24 bits as a float in [0, 1): exact, and never rounds up to 1.
inline float toUnitFloat(uint32_t x) {
  return float(x >> 8) * 0x1p-24f;
}

#if defined(__SSE4_1__)
// reverseBits of every 32-bit lane with byte shuffles (x86 has no bit-reverse instruction, and
// the sixteen shifts and masks of reverseBits were half of the sampler's instructions): each
// byte's two nibbles are reversed through a 16-entry table and swapped, then each lane's bytes.
inline __m128i reverseLaneBits(__m128i v) {
  const __m128i lowNibble = _mm_set1_epi8(0x0f);
  // reverse(n) for a nibble n, and reverse(n) << 4.
  const __m128i reversed =
      _mm_setr_epi8(0x0, 0x8, 0x4, 0xc, 0x2, 0xa, 0x6, 0xe, 0x1, 0x9, 0x5, 0xd, 0x3, 0xb, 0x7, 0xf);
  const __m128i reversedHigh = _mm_slli_epi16(reversed, 4);  // no byte exceeds 0xf: no carry
  const __m128i low = _mm_and_si128(v, lowNibble);
  const __m128i high = _mm_and_si128(_mm_srli_epi16(v, 4), lowNibble);
  const __m128i bytes =
      _mm_or_si128(_mm_shuffle_epi8(reversedHigh, low), _mm_shuffle_epi8(reversed, high));
  return _mm_shuffle_epi8(bytes,
                          _mm_setr_epi8(3, 2, 1, 0, 7, 6, 5, 4, 11, 10, 9, 8, 15, 14, 13, 12));
}

inline uint32_t reverseBitsFast(uint32_t x) {
  return uint32_t(_mm_cvtsi128_si32(reverseLaneBits(_mm_cvtsi32_si128(int(x)))));
}

// toUnitFloat(reverseBits(lane)) of every lane.
inline __m128 reversedUnitFloats4(__m128i v) {
  return _mm_mul_ps(_mm_cvtepi32_ps(_mm_srli_epi32(reverseLaneBits(v), 8)), _mm_set1_ps(0x1p-24f));
}

// toUnitFloat(reverseBits(x)), toUnitFloat(reverseBits(y)), both at once.
inline Vec2f reversedUnitFloats(uint32_t x, uint32_t y) {
  float lanes[4];
  _mm_storeu_ps(lanes, reversedUnitFloats4(_mm_insert_epi32(_mm_cvtsi32_si128(int(x)), int(y), 1)));
  return {lanes[0], lanes[1]};
}
#else
inline uint32_t reverseBitsFast(uint32_t x) {
  return reverseBits(x);
}

inline Vec2f reversedUnitFloats(uint32_t x, uint32_t y) {
  return {toUnitFloat(reverseBits(x)), toUnitFloat(reverseBits(y))};
}
#endif

}  // namespace

void Sampler::startPixelSample(int px, int py, uint32_t indexInSubBuffer, int subBuffer) {
  if (px != pixelX_ || py != pixelY_) {
    pixelX_ = px;
    pixelY_ = py;
    for (SubBufferSeeds& s : seeds_) s.subBuffer = -1;
  }
  // One slot per sub-buffer (K ≤ 4 in practice); a slot holding another sub-buffer starts over.
  current_ = &seeds_[uint32_t(subBuffer) % kSeedSlots];
  if (current_->subBuffer != subBuffer) {
    uint64_t h = hashCombine(mix64(seed_), uint64_t(uint32_t(px)));
    h = hashCombine(h, uint64_t(uint32_t(py)));
    current_->pixelHash = hashCombine(h, uint64_t(uint32_t(subBuffer)));
    current_->subBuffer = subBuffer;
    current_->filled = 0;
  }
  reversedIndex_ = reverseBitsFast(indexInSubBuffer);
  dimension_ = 0;
}

// The cached seeds when present (inlined into the draws), else computed out of line.
inline Sampler::DimensionSeeds Sampler::seeds(uint32_t dimension) {
  if (dimension < kCachedDimensions && (current_->filled >> dimension & 1))
    return current_->seeds[dimension];
  return computeSeeds(dimension);
}

Sampler::DimensionSeeds Sampler::computeSeeds(uint32_t dimension) {
  const uint64_t h = hashCombine(current_->pixelHash, dimension);
  const DimensionSeeds s{h, mix64(h)};
  if (dimension < kCachedDimensions) {
    current_->seeds[dimension] = s;
    current_->filled |= uint64_t(1) << dimension;
  }
  return s;
}

// Every call draws from its own (0,2)-sequence: the pair of dimensions gets an independent
// index shuffle and independent scrambles (Burley 2020, §4 "padding"), so the points of one
// call are stratified within the pixel while different calls are mutually independent.
Vec2f Sampler::get2D() {
  const Vec2f u = get2DAt(dimension_);
  dimension_ += 2;
  return u;
}

Vec2f Sampler::get2DAt(uint32_t dimension) {
  const DimensionSeeds seed = seeds(dimension);
  const uint64_t h = seed.first, h2 = seed.second;
  // shuffled index i = reverseBits(z); dimension 0 of i is reverseBits(i) = z, whose scramble
  // is reverseBits(lowerBitsPermutation(reverseBits(z), ·)); dimension 1 likewise.
  const uint32_t z = lowerBitsPermutation(reversedIndex_, uint32_t(h));
  return reversedUnitFloats(lowerBitsPermutation(reverseBitsFast(z), uint32_t(h >> 32)),
                            lowerBitsPermutation(reversedSobolDimension1(z), uint32_t(h2)));
}

float Sampler::get1DAt(uint32_t dimension) {
  const uint64_t h = seeds(dimension).first;
  const uint32_t z = lowerBitsPermutation(reversedIndex_, uint32_t(h));
  return toUnitFloat(reverseBitsFast(lowerBitsPermutation(reverseBitsFast(z), uint32_t(h >> 32))));
}

#if defined(__SSE4_1__)
// The steps of get1DAt / get2DAt, each for all five draws at once: the shuffled indices z, then
// the scrambles of the first coordinates (of reverseBits(z)) and of the two second coordinates
// (of the second Sobol dimension of z), then the reversals into floats.
Sampler::BounceDraws Sampler::getBounce(uint32_t first) {
  const DimensionSeeds lobe = seeds(first), direction = seeds(first + 1), light = seeds(first + 3),
                       lightPoint = seeds(first + 4), roulette = seeds(first + 6);
  const auto low = [](uint64_t h) { return uint32_t(h); };
  const auto high = [](uint64_t h) { return uint32_t(h >> 32); };
  const Lanes z = lowerBitsPermutation(
      Lanes{reversedIndex_, reversedIndex_, reversedIndex_, reversedIndex_},
      Lanes{low(lobe.first), low(direction.first), low(light.first), low(lightPoint.first)});
  const uint32_t zRoulette = lowerBitsPermutation(reversedIndex_, low(roulette.first));
  const Lanes firstCoordinates = lowerBitsPermutation(
      Lanes(reverseLaneBits(__m128i(z))),
      Lanes{high(lobe.first), high(direction.first), high(light.first), high(lightPoint.first)});
  const Lanes otherCoordinates = lowerBitsPermutation(
      Lanes{reversedSobolDimension1(z[1]), reversedSobolDimension1(z[3]),
            reverseBitsFast(zRoulette), 0},
      Lanes{low(direction.second), low(lightPoint.second), high(roulette.first), 0});
  float a[4], b[4];
  _mm_storeu_ps(a, reversedUnitFloats4(__m128i(firstCoordinates)));
  _mm_storeu_ps(b, reversedUnitFloats4(__m128i(otherCoordinates)));
  return {a[0], {a[1], b[0]}, a[2], {a[3], b[1]}, b[2]};
}
#else
Sampler::BounceDraws Sampler::getBounce(uint32_t first) {
  return {get1DAt(first), get2DAt(first + 1), get1DAt(first + 3), get2DAt(first + 4),
          get1DAt(first + 6)};
}
#endif

Vec2f Sampler::getPixel2D() {
  return get2D();
}

}  // namespace chorus::render
