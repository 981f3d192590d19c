// PNG output: expected bytes for a few values through each tonemapper, computed by hand from
// the formulas in tonemap.h.
#include <gtest/gtest.h>
#include <stb_image.h>

#include "common/error.h"
#include "common/image/false_color.h"
#include "common/image/png_io.h"
#include "tests/support/test_support.h"

namespace chorus {
namespace {

std::vector<uint8_t> decode(const std::filesystem::path& path, int expectChannels) {
  int w = 0, h = 0, n = 0;
  unsigned char* pixels = stbi_load(path.c_str(), &w, &h, &n, 0);
  EXPECT_NE(pixels, nullptr);
  EXPECT_EQ(n, expectChannels);
  std::vector<uint8_t> out(pixels, pixels + size_t(w) * size_t(h) * size_t(n));
  stbi_image_free(pixels);
  return out;
}

// Hand values: sRGB(v) = 1.055 v^(1/2.4) − 0.055 (v > 0.0031308), else 12.92 v.
//   clamp 0.5        → sRGB(0.5) = 0.73536  → 187.5 → 188
//   clamp 0.002      → 12.92·0.002 = 0.02584 → 6.59 → 7
//   clamp 3.0        → 1 → 255;  −1 → 0;  NaN → 0
//   reinhard 1.0     → 0.5 → 188;  reinhard 3.0 → 0.75 → sRGB 0.88082 → 224.6 → 225
//   aces 1.0         → 2.54/3.16 = 0.80380 → sRGB 0.90821 → 231.6 → 232
//   exposure +1, clamp 0.25 → 0.5 → 188
TEST(Png, TonemappersProduceHandComputedBytes) {
  test::TempDir dir;
  Image image(3, 2, 3);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float values[] = {0.5f, 0.002f, 3.0f, -1.0f, nan, 1.0f};
  for (int i = 0; i < 6; ++i)
    for (int c = 0; c < 3; ++c) image(i % 3, i / 3, c) = values[i];

  writePng(dir / "clamp.png", image, {0.0f, Tonemapper::Clamp});
  const auto clamp = decode(dir / "clamp.png", 3);
  const uint8_t expectClamp[] = {188, 7, 255, 0, 0, 255};
  for (int i = 0; i < 6; ++i) EXPECT_EQ(clamp[size_t(3 * i)], expectClamp[i]) << "pixel " << i;

  writePng(dir / "reinhard.png", image, {0.0f, Tonemapper::Reinhard});
  const auto reinhard = decode(dir / "reinhard.png", 3);
  EXPECT_EQ(reinhard[3 * 5], 188);  // 1.0
  EXPECT_EQ(reinhard[3 * 2], 225);  // 3.0

  writePng(dir / "aces.png", image, {0.0f, Tonemapper::AcesFit});
  EXPECT_EQ(decode(dir / "aces.png", 3)[3 * 5], 232);

  Image quarter(1, 1, 1, 0.25f);
  writePng(dir / "exposure.png", quarter, {1.0f, Tonemapper::Clamp});
  EXPECT_EQ(decode(dir / "exposure.png", 1)[0], 188);
}

// Every channel layout, at a size with many rows and odd widths: an independent decoder
// (stb_image) reads back exactly the bytes the tonemapping chain gives for each value.
TEST(Png, DecodesToTheDisplayBytesForEveryLayout) {
  test::TempDir dir;
  for (int channels : {1, 3, 4}) {
    Image image(37, 29, channels);
    for (int y = 0; y < image.height(); ++y)
      for (int x = 0; x < image.width(); ++x)
        for (int c = 0; c < channels; ++c)  // a ramp with jumps, values outside [0, 1] too
          image(x, y, c) =
              1.3f * std::fmod(0.037f * float(x * (c + 1)) + 0.11f * float(y), 1.0f) - 0.1f;
    const auto path = dir / ("layout" + std::to_string(channels) + ".png");
    writePng(path, image, {0.0f, Tonemapper::Clamp});
    const auto bytes = decode(path, channels);
    ASSERT_EQ(bytes.size(), image.size());
    for (size_t i = 0; i < bytes.size(); ++i) {
      const float v = image.data()[i];
      const uint8_t expected =
          channels == 4 && i % 4 == 3
              ? uint8_t(std::lround(255.0f * std::clamp(v, 0.0f, 1.0f)))  // alpha: linear
              : toDisplayByte(v, {0.0f, Tonemapper::Clamp});
      ASSERT_EQ(bytes[i], expected) << channels << " channels, byte " << i;
    }
  }
}

TEST(Png, RejectsUnsupportedChannelCounts) {
  test::TempDir dir;
  EXPECT_THROW(writePng(dir / "x.png", Image(2, 2, 2)), Error);
  EXPECT_FALSE(std::filesystem::exists(dir / "x.png"));
}

TEST(FalseColor, EndpointsAndMonotoneLuminance) {
  Image ramp(11, 1, 1);
  for (int x = 0; x <= 10; ++x) ramp(x, 0, 0) = float(x) / 10;
  ramp(0, 0, 0) = -5.0f;  // clamps to the first stop
  const Image colors = falseColor(ramp);
  test::TempDir dir;
  writePng(dir / "ramp.png", colors);
  const auto bytes = decode(dir / "ramp.png", 3);
  // The stops written as 8-bit: 0 → (0.15, 0.05, 0.35)·255 = (38, 13, 89), 1 → (250, 230, 38).
  EXPECT_NEAR(bytes[0], 38, 1);
  EXPECT_NEAR(bytes[1], 13, 1);
  EXPECT_NEAR(bytes[2], 89, 1);
  EXPECT_NEAR(bytes[30], 250, 1);
  EXPECT_NEAR(bytes[31], 230, 1);
  EXPECT_NEAR(bytes[32], 38, 1);
  // Brightness grows along the ramp, so the map reads as ordered in grey too.
  for (int x = 1; x <= 10; ++x)
    EXPECT_GT(colors(x, 0, 0) * 0.2126f + colors(x, 0, 1) * 0.7152f + colors(x, 0, 2) * 0.0722f,
              colors(x - 1, 0, 0) * 0.2126f + colors(x - 1, 0, 1) * 0.7152f +
                  colors(x - 1, 0, 2) * 0.0722f)
        << x;
}

}  // namespace
}  // namespace chorus
