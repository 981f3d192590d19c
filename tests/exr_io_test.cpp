// EXR round trips (float and half, many layers, odd sizes), foreign single-layer files, and
// clean errors on bad input.
#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <ImfOutputFile.h>
#include <gtest/gtest.h>

#include <fstream>

#include "common/error.h"
#include "common/image/exr_io.h"
#include "tests/support/test_support.h"

namespace chorus {
namespace {
using test::TempDir;

// Half has 11 significant bits: relative error ≤ 2^-11 for normal values, absolute error
// ≤ 2^-25 for subnormals.
void expectNear(const Image& a, const Image& b, float relTolerance) {
  const float absTolerance = relTolerance > 0 ? 3.0e-8f : 0.0f;
  ASSERT_TRUE(a.sameShape(b));
  for (size_t i = 0; i < a.size(); ++i)
    ASSERT_NEAR(a.data()[i], b.data()[i], relTolerance * std::abs(b.data()[i]) + absTolerance)
        << "element " << i;
}

class ExrRoundTrip : public ::testing::TestWithParam<std::tuple<int, int, ExrPixelType>> {};

TEST_P(ExrRoundTrip, ManyLayersSurvive) {
  const auto [w, h, type] = GetParam();
  TempDir dir;
  std::vector<ExrLayer> layers = {
      {"", test::randomImage(w, h, 3, 1, -2.0f, 100.0f)},
      {"albedo", test::randomImage(w, h, 3, 2)},
      {"depth", test::randomImage(w, h, 1, 3, 0.0f, 1000.0f)},
      {"sub0.color", test::randomImage(w, h, 3, 4)},
      {"rgba", test::randomImage(w, h, 4, 5)},
      {"uv", test::randomImage(w, h, 2, 6)},
      {"many", test::randomImage(w, h, 7, 7)},
  };
  const auto path = dir / "layers.exr";
  writeExr(path, layers, type);
  const std::vector<ExrLayer> back = readExr(path);
  ASSERT_EQ(back.size(), layers.size());
  const float tolerance = type == ExrPixelType::Half ? 1.0f / 2048 : 0.0f;
  for (const ExrLayer& layer : layers) {
    const ExrLayer* read = findLayer(back, layer.name);
    ASSERT_NE(read, nullptr) << layer.name;
    expectNear(read->image, layer.image, tolerance);
  }
  // The default layer comes first, as viewers show it.
  EXPECT_EQ(back[0].name, "");
}

INSTANTIATE_TEST_SUITE_P(Sizes, ExrRoundTrip,
                         ::testing::Combine(::testing::Values(1, 257), ::testing::Values(1, 131),
                                            ::testing::Values(ExrPixelType::Float,
                                                              ExrPixelType::Half)));

TEST(Exr, ChannelNamesFollowTheDocumentedScheme) {
  TempDir dir;
  writeExr(dir / "a.exr", {{"", Image(2, 2, 3)}, {"depth", Image(2, 2, 1)}, {"n", Image(2, 2, 4)}});
  Imf::InputFile file((dir / "a.exr").c_str());
  std::vector<std::string> names;
  for (auto it = file.header().channels().begin(); it != file.header().channels().end(); ++it)
    names.push_back(it.name());
  // EXR stores channels alphabetically.
  EXPECT_EQ(names,
            (std::vector<std::string>{"B", "G", "R", "depth.Y", "n.A", "n.B", "n.G", "n.R"}));
}

// Writes a file the way other tools do: plain R,G,B (or Y) channels, half, with a data window
// that does not start at 0.
void writeForeign(const std::filesystem::path& path, const std::vector<std::string>& channels,
                  int w, int h, float value) {
  Imf::Header header(Imath::Box2i({0, 0}, {w + 9, h + 4}), Imath::Box2i({10, 5}, {w + 9, h + 4}));
  for (const auto& c : channels) header.channels().insert(c, Imf::Channel(Imf::HALF));
  std::vector<half> pixels(size_t(w) * size_t(h), half(value));
  Imf::FrameBuffer frame;
  for (size_t i = 0; i < channels.size(); ++i) {
    char* origin = reinterpret_cast<char*>(pixels.data()) - 10 * 2 - 5 * 2 * w;
    frame.insert(channels[i], Imf::Slice(Imf::HALF, origin, 2, size_t(2 * w)));
  }
  Imf::OutputFile file(path.c_str(), header);
  file.setFrameBuffer(frame);
  file.writePixels(h);
}

TEST(Exr, ReadsForeignSingleLayerFiles) {
  TempDir dir;
  writeForeign(dir / "rgb.exr", {"R", "G", "B"}, 5, 3, 0.25f);
  writeForeign(dir / "y.exr", {"Y"}, 4, 2, 2.0f);
  writeForeign(dir / "rgba.exr", {"R", "G", "B", "A"}, 3, 3, 1.5f);
  const Image rgb = readExrLayer(dir / "rgb.exr");
  EXPECT_EQ(rgb.width(), 5);
  EXPECT_EQ(rgb.height(), 3);
  EXPECT_EQ(rgb.channels(), 3);
  EXPECT_EQ(rgb.at(4, 2, 2), 0.25f);
  const Image y = readExrLayer(dir / "y.exr");
  EXPECT_EQ(y.channels(), 1);
  EXPECT_EQ(y.at(3, 1, 0), 2.0f);
  EXPECT_EQ(readExrLayer(dir / "rgba.exr").channels(), 4);
}

TEST(Exr, UnknownExtraLayerIsKeptAndIgnorable) {
  TempDir dir;
  writeExr(dir / "x.exr", {{"", Image(3, 3, 3, 1.0f)}, {"mystery", Image(3, 3, 5, 2.0f)}});
  EXPECT_EQ(readExrLayer(dir / "x.exr").at(1, 1, 0), 1.0f);
  EXPECT_EQ(readExrLayer(dir / "x.exr", "mystery").channels(), 5);
}

TEST(Exr, MissingLayerNamesTheAvailableOnes) {
  TempDir dir;
  writeExr(dir / "x.exr", {{"", Image(3, 3, 3)}, {"depth", Image(3, 3, 1)}});
  try {
    readExrLayer(dir / "x.exr", "normal");
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("depth"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("x.exr"), std::string::npos) << e.what();
  }
}

TEST(Exr, BadFilesGiveErrorsNotCrashes) {
  TempDir dir;
  EXPECT_THROW(readExr(dir / "missing.exr"), Error);
  std::ofstream(dir / "text.exr") << "this is not an EXR file";
  EXPECT_THROW(readExr(dir / "text.exr"), Error);
  // Truncate a valid file at several points.
  writeExr(dir / "full.exr", test::randomImage(64, 64, 3, 9));
  std::ifstream in(dir / "full.exr", std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), {});
  for (size_t keep : {size_t(3), size_t(40), bytes.size() / 2, bytes.size() - 10}) {
    const auto cut = dir / ("cut" + std::to_string(keep) + ".exr");
    std::ofstream(cut, std::ios::binary).write(bytes.data(), std::streamsize(keep));
    EXPECT_THROW(readExr(cut), Error) << "kept " << keep << " bytes";
  }
}

TEST(Exr, FailedWriteLeavesExistingFileIntact) {
  TempDir dir;
  const auto path = dir / "keep.exr";
  writeExr(path, Image(2, 2, 3, 7.0f));
  // Layers of different sizes are rejected before anything is written.
  EXPECT_THROW(writeExr(path, {{"", Image(2, 2, 3)}, {"b", Image(3, 3, 3)}}), Error);
  EXPECT_EQ(readExrLayer(path).at(1, 1, 1), 7.0f);
  EXPECT_THROW(writeExr(dir / "no_such_dir" / "x.exr", Image(2, 2, 3)), Error);
  // No temporary files left behind.
  int files = 0;
  for (auto& entry : std::filesystem::directory_iterator(dir.path())) (void)entry, ++files;
  EXPECT_EQ(files, 1);
}

}  // namespace
}  // namespace chorus
