// Reading Tungsten's buffer directories: a synthetic one written here, and the peer data when
// ../shared is present.
#include <gtest/gtest.h>

#include <fstream>

#include "common/error.h"
#include "common/image/exr_io.h"
#include "denoise/buffers/tungsten_dir.h"
#include "tests/support/test_support.h"

namespace chorus {
namespace {

void writeSynthetic(const std::filesystem::path& dir, int w, int h) {
  for (Quantity q : kAllQuantities) {
    const std::string name(quantityName(q));
    const int c = channelCount(q);
    writeExr(dir / (name + ".exr"), Image(w, h, c, 1.0f), ExrPixelType::Half);
    writeExr(dir / (name + "A.exr"), Image(w, h, c, 0.5f), ExrPixelType::Half);
    writeExr(dir / (name + "B.exr"), Image(w, h, c, 1.5f), ExrPixelType::Half);
    writeExr(dir / (name + "Variance.exr"), Image(w, h, c, 0.25f), ExrPixelType::Half);
  }
}

TEST(TungstenDir, ReadsAllBuffersWithHalfVariances) {
  test::TempDir dir;
  writeSynthetic(dir.path(), 6, 4);
  std::ofstream(dir / "meta.json") << R"({"spp": 16})";
  ASSERT_TRUE(isTungstenDirectory(dir.path()));
  const DenoiseInput in = readTungstenDirectory(dir.path());
  ASSERT_TRUE(in.halves.has_value());
  EXPECT_EQ(in.width(), 6);
  EXPECT_EQ(in.whole.depth.mean.channels(), 1);
  EXPECT_EQ(in.halves->at(0).color.mean.at(5, 3, 2), 0.5f);
  EXPECT_EQ(in.halves->at(1).normal.mean.at(0, 0, 0), 1.5f);
  // A half has twice the variance of the mean of the whole.
  EXPECT_EQ(in.halves->at(1).albedo.varianceOfMean.at(2, 2, 1), 0.5f);
  EXPECT_EQ(in.whole.sampleCount.at(0, 0, 0), 16.0f);
  EXPECT_EQ(in.halves->at(0).sampleCount.at(0, 0, 0), 8.0f);
}

TEST(TungstenDir, MissingOrMismatchedFilesAreNamed) {
  test::TempDir dir;
  writeSynthetic(dir.path(), 6, 4);
  writeExr(dir / "depthB.exr", Image(5, 4, 1), ExrPixelType::Half);
  try {
    readTungstenDirectory(dir.path());
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("depthB.exr"), std::string::npos) << e.what();
  }
  std::filesystem::remove(dir / "normalVariance.exr");
  EXPECT_THROW(readTungstenDirectory(dir.path()), Error);
}

TEST(TungstenDir, ReadsThePeerData) {
  CHORUS_REQUIRE_SHARED(shared);
  const auto dir = shared / "peers/tungsten-nfor/room/spp4";
  const DenoiseInput in = readTungstenDirectory(dir);
  EXPECT_EQ(in.width(), 256);
  EXPECT_EQ(in.height(), 256);
  EXPECT_EQ(in.whole.sampleCount.at(0, 0, 0), 4.0f);
  // ../shared/peers/tungsten-nfor/README.md counts 18265 NaN pixels in visibilityVariance.exr for
  // this case.
  int nanPixels = 0;
  for (float v : in.whole.visibility.varianceOfMean.values()) nanPixels += std::isnan(v);
  EXPECT_EQ(nanPixels, 18265);
}

}  // namespace
}  // namespace chorus
