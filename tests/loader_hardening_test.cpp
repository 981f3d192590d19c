// Issue 27, file inputs: every malformed or hostile file the fuzzing campaign found (and the
// ones found while fixing them) fails with one chorus::Error line naming the file, through
// the library and through the CLI (exit code 2), instead of crashing, hanging or exhausting
// memory. The inputs live in tests/inputs/hardening (make_inputs.py writes them;
// docs/hardening-inputs.md lists the findings); FIFOs cannot be committed and are made here.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <stb_image.h>
#include <stb_image_write.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstring>
#include <fstream>
#include <random>
#include <thread>

#include "common/error.h"
#include "common/image/exr_io.h"
#include "denoise/buffers/tungsten_dir.h"
#include "renderer/scene/environment.h"
#include "renderer/scene/gltf_loader.h"
#include "renderer/scene/radiance_hdr.h"
#include "renderer/scene/scene.h"
#include "renderer/scene/scene_limits.h"
#include "tests/support/gltf_builder.h"
#include "tests/support/test_support.h"

namespace chorus {
namespace {

namespace fs = std::filesystem;
using test::runChorus;
using test::TempDir;

fs::path input(const std::string& name) {
  return test::sourceDir() / "tests" / "inputs" / "hardening" / name;
}

// The message of the chorus::Error `f` throws ("" when it throws nothing).
template <typename F>
std::string errorOf(F&& f) {
  try {
    f();
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

// One line that names `file` and contains `fragment`.
void expectOneLineError(const std::string& message, const fs::path& file,
                        const std::string& fragment) {
  EXPECT_NE(message.find(file.string()), std::string::npos) << message;
  EXPECT_NE(message.find(fragment), std::string::npos) << message;
  EXPECT_EQ(message.find('\n'), std::string::npos) << message;
}

// The CLI's answer to bad input: exit code 2, one stderr line naming the file.
void expectCliError(const test::ProcessResult& r, const std::string& name,
                    const std::string& fragment) {
  EXPECT_EQ(r.exitCode, 2) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_NE(r.err.find(name), std::string::npos) << r.err;
  EXPECT_NE(r.err.find(fragment), std::string::npos) << r.err;
}

struct BadScene {
  const char* file;
  const char* fragment;  // part of the expected message
};

// Each committed glTF input and what the error must say.
const BadScene kBadScenes[] = {
    {"accessor-count-wraps.gltf",
     "has count 6148914691236517206; chorus reads accessors of at "
     "most 268435456 elements"},
    {"accessor-count-2e63.gltf", "has count 9223372036854775808"},
    {"accessor-count-2e62.gltf", "has count 4611686018427387904"},
    {"accessor-count-2e32.gltf", "has count 4294967296"},
    {"accessor-offset-wraps.gltf", "reads past the end of bufferView 0"},
    {"sparse-count-exceeds-count.gltf", "has more sparse values (7) than elements"},
    {"sparse-signed-indices.gltf", "sparse indices of an invalid type"},
    {"image-view-outside-buffer.gltf", "image 0 lies outside buffer 0"},
    {"deep-extras.gltf", "nests JSON arrays or objects more than 128 levels deep"},
    {"deep-extras.glb", "nests JSON arrays or objects more than 128 levels deep"},
    {"node-dag-24-levels.gltf", "more than 1048576 node instances"},
    {"vertex-at-1e20.gltf",
     "node 0 mesh 0 primitive 0 has a vertex at (1e+20, 0, 0), outside "
     "the supported range of ±1e+12"},
    {"node-scale-1e20.gltf", "has a vertex at (1e+20, 0, 0)"},
    {"camera-at-1e20.gltf", "camera node 1 is at (0, 0, 1e+20), outside"},
    {"orthographic-ymag-1e20.gltf", "ymag 1e+20; each must lie in (0, 1e+12]"},
    {"orthographic-xmag-1e-30.gltf", "aspect ratio 1e-30, outside the supported 0.03125"},
    {"perspective-aspect-1e30.gltf", "aspect ratio 1e+30"},
    {"light-at-1e20.gltf", "light node 1 is at (0, 1e+20, 0)"},
    {"light-intensity-1e300.gltf", "intensity is 1e+300, outside the supported range of ±1e+09"},
    {"emissive-strength-1e300.gltf", "material 0 has emissiveStrength 1e+300"},
    {"texture-claims-20000x20000.gltf", "cannot decode image 'image 0': too large"},
    {"buffer-uri-directory.gltf", "is a directory, not a file"},
};

TEST(LoaderHardening, EveryBadSceneIsOneErrorNamingTheFile) {
  for (const BadScene& s : kBadScenes) {
    SCOPED_TRACE(s.file);
    const fs::path path = input(s.file);
    expectOneLineError(errorOf([&] { render::loadGltf(path); }), path, s.fragment);
  }
}

TEST(LoaderHardening, InfoAndRenderExitWithCode2AndOneLine) {
  TempDir dir;
  for (const BadScene& s : kBadScenes) {
    SCOPED_TRACE(s.file);
    const std::string path = input(s.file).string();
    expectCliError(runChorus({"info", path}), s.file, s.fragment);
    expectCliError(runChorus({"render", path, "--width", "8", "--height", "8", "--spp", "1",
                              "--denoise", "none", "--quiet", "--out", (dir / "out").string()}),
                   s.file, s.fragment);
    EXPECT_FALSE(fs::exists(dir / "out" / "render.exr"));
  }
}

TEST(LoaderHardening, SweepExitsWithCode2AndOneLine) {
  TempDir dir;
  const std::string path = input("accessor-count-wraps.gltf").string();
  expectCliError(
      runChorus({"sweep", path, "--out", (dir / "sweep").string(), "--spp", "1", "--methods",
                 "atrous", "--reference-spp", "1", "--width", "8", "--height", "8", "--quiet"}),
      "accessor-count-wraps.gltf", "has count 6148914691236517206");
}

// A file of the limits' size is never read: the budgets are charged from the accessor counts.
// 2^28 strip indices over 2^28 vertices need about 56 GB (scene_limits.h's bytes per triangle
// and vertex), so a machine with less memory refuses the scene before reading its data.
TEST(LoaderHardening, SceneLargerThanMemoryIsRefusedBeforeItsDataIsRead) {
  const double memory = double(sysconf(_SC_PHYS_PAGES)) * double(sysconf(_SC_PAGE_SIZE));
  const double needed = double(render::kMaxSceneTriangles - 2) * render::kBytesPerTriangle +
                        double(render::kMaxSceneVertices) * render::kBytesPerVertex;
  if (memory >= needed) GTEST_SKIP() << "this machine holds a scene at the limits";
  TempDir dir;
  test::GltfBuilder b;
  const int p = b.addPositions({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}});
  const int i = b.addIndices({0, 1, 2});
  b.root()["accessors"][size_t(p)]["count"] = render::kMaxSceneVertices;
  b.root()["accessors"][size_t(i)]["count"] = render::kMaxSceneVertices;
  b.addNode({{"mesh", b.addMesh({test::GltfBuilder::primitive(p, i, -1, -1, -1, 5)})}});
  b.writeGltf(dir / "huge.gltf");
  expectOneLineError(
      errorOf([&] { render::loadGltf(dir / "huge.gltf"); }), dir / "huge.gltf",
      "loading 268435454 triangles and 268435456 vertices (instances included) needs");
}

// While alive, keeps opening the write end of `fifo` (non-blocking), so that a reader blocked
// in open() on it is released and sees end of file: a regression then fails instead of hanging.
class FifoWatchdog {
 public:
  explicit FifoWatchdog(fs::path fifo)
      : fifo_(std::move(fifo)), thread_([this] {
          while (!done_) {
            const int fd = ::open(fifo_.c_str(), O_WRONLY | O_NONBLOCK);
            if (fd >= 0) ::close(fd);
            std::this_thread::sleep_for(std::chrono::milliseconds(50));
          }
        }) {}
  ~FifoWatchdog() {
    done_ = true;
    thread_.join();
  }

 private:
  fs::path fifo_;
  std::atomic<bool> done_{false};
  std::thread thread_;
};

TEST(LoaderHardening, OnlyRegularFilesAreOpened) {
  TempDir dir;
  const fs::path fifo = dir / "fifo";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  FifoWatchdog watchdog(fifo);
  const std::string notRegular = "is not a regular file (a FIFO, socket or device)";

  // A scene whose external buffer is the FIFO (writeGltf names the buffer after the file).
  test::GltfBuilder b;
  b.addTriangleMesh({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, {0, 1, 2}, -1);
  b.writeGltf(dir / "buffer-fifo.gltf", true);
  {
    std::ifstream in(dir / "buffer-fifo.gltf");
    nlohmann::json j = nlohmann::json::parse(in);
    j["buffers"][0]["uri"] = "fifo";
    std::ofstream(dir / "buffer-fifo.gltf") << j.dump();
  }
  expectOneLineError(errorOf([&] { render::loadGltf(dir / "buffer-fifo.gltf"); }),
                     dir / "buffer-fifo.gltf", "cannot read " + fifo.string() + ": " + notRegular);
  expectOneLineError(errorOf([&] { render::loadGltf(fifo); }), fifo, notRegular);
  expectOneLineError(errorOf([&] { render::loadEnvironmentImage(dir / "fifo.hdr"); }),
                     dir / "fifo.hdr", "no such file");
  fs::create_symlink(fifo, dir / "fifo.hdr");
  expectOneLineError(errorOf([&] { render::loadEnvironmentImage(dir / "fifo.hdr"); }),
                     dir / "fifo.hdr", notRegular);
  fs::create_symlink(fifo, dir / "fifo.exr");
  expectOneLineError(errorOf([&] { readExr(dir / "fifo.exr"); }), dir / "fifo.exr", notRegular);
  expectOneLineError(errorOf([&] { readExr(dir.path()); }), dir.path(),
                     "is a directory, not a file");

  // Through the CLI: the scene and --env.
  expectCliError(runChorus({"info", fifo.string()}), fifo.string(), notRegular);
  expectCliError(
      runChorus({"render", (test::sourceDir() / "scenes" / "cornell-box.gltf").string(), "--env",
                 (dir / "fifo.hdr").string(), "--width", "8", "--height", "8", "--spp", "1",
                 "--denoise", "none", "--quiet", "--out", (dir / "out").string()}),
      "fifo.hdr", notRegular);
}

// Radiance HDR ---------------------------------------------------------------------------------

// stb_image's decoding of a file that it reads correctly, as 3-channel floats.
std::vector<float> stbDecode(const fs::path& path, int* width, int* height) {
  int channels = 0;
  float* pixels = stbi_loadf(path.c_str(), width, height, &channels, 3);
  if (!pixels) return {};
  std::vector<float> values(pixels, pixels + size_t(*width) * size_t(*height) * 3);
  stbi_image_free(pixels);
  return values;
}

void expectSameBitsAsStb(const fs::path& path) {
  int width = 0, height = 0;
  const std::vector<float> expected = stbDecode(path, &width, &height);
  ASSERT_FALSE(expected.empty()) << stbi_failure_reason();
  const Image image = render::readRadianceHdr(path);
  ASSERT_EQ(image.width(), width);
  ASSERT_EQ(image.height(), height);
  ASSERT_EQ(image.channels(), 3);
  for (size_t i = 0; i < expected.size(); ++i)
    ASSERT_EQ(std::memcmp(&image.values()[i], &expected[i], sizeof(float)), 0)
        << path << " value " << i << ": " << image.values()[i] << " vs " << expected[i];
}

TEST(RadianceHdr, DecodesLikeStbBitForBit) {
  expectSameBitsAsStb(input("env-valid-rle.hdr"));
  expectSameBitsAsStb(input("env-valid-flat.hdr"));
  // stb_image_write's files: run-length scanlines for widths 8 … 32767, flat below, over a
  // range of exponents (including black and subnormal-scaled texels).
  TempDir dir;
  std::mt19937 rng(27);
  std::uniform_real_distribution<float> exponent(-30.0f, 20.0f);
  for (const auto& [w, h] : {std::pair{5, 3}, {8, 2}, {131, 7}, {300, 4}}) {
    std::vector<float> values(size_t(w) * size_t(h) * 3);
    for (size_t i = 0; i < values.size(); ++i)
      values[i] = i % 17 == 0 ? 0.0f : std::exp2(exponent(rng));
    // Runs: a constant stretch in every row.
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < std::min(w, 140); ++x)
        for (int c = 0; c < 3; ++c)
          values[(size_t(y) * size_t(w) + size_t(x)) * 3 + size_t(c)] = 0.75f;
    SCOPED_TRACE(testing::Message() << w << "x" << h);
    const fs::path path = dir / "stb-written.hdr";
    ASSERT_TRUE(stbi_write_hdr(path.c_str(), w, h, 3, values.data()));
    expectSameBitsAsStb(path);
  }
}

TEST(RadianceHdr, DecodesTheSharedPanoramasLikeStb) {
  CHORUS_REQUIRE_SHARED(shared);
  int count = 0;
  for (const fs::directory_entry& entry :
       fs::directory_iterator(shared / "scenes" / "_environments"))
    if (entry.path().extension() == ".hdr") {
      SCOPED_TRACE(entry.path().string());
      expectSameBitsAsStb(entry.path());
      ++count;
    }
  EXPECT_GT(count, 0);
}

TEST(RadianceHdr, FlatPixelDecodesToItsRgbeValue) {
  // (128, 64, 32) · 2^(129 − 136) = (1, 0.5, 0.25): RGBE's definition, independent of any decoder.
  const Image image = render::readRadianceHdr(input("env-valid-flat.hdr"));
  ASSERT_EQ(image.width(), 4);
  EXPECT_EQ(image.at(3, 0, 0), 1.0f);
  EXPECT_EQ(image.at(3, 0, 1), 0.5f);
  EXPECT_EQ(image.at(3, 0, 2), 0.25f);
}

TEST(RadianceHdr, MalformedFilesAreErrorsNotEndlessLoops) {
  const struct {
    const char* file;
    const char* fragment;
  } cases[] = {
      {"env-truncated-rle.hdr", "is truncated (the pixel data ends early)"},
      {"env-zero-length-run.hdr", "has a corrupt run-length scanline"},
  };
  for (const auto& c : cases) {
    const fs::path path = input(c.file);
    expectOneLineError(errorOf([&] { render::readRadianceHdr(path); }), path, c.fragment);
  }
  TempDir dir;
  const auto write = [&](const std::string& name, const std::string& bytes) {
    std::ofstream(dir / name, std::ios::binary) << bytes;
    return dir / name;
  };
  const std::string header = "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n";
  // Sizes are checked against the bytes present before anything is allocated.
  fs::path p = write("huge.hdr", header + "-Y 16000 +X 16000\n" + std::string(64, '\2'));
  expectOneLineError(errorOf([&] { render::readRadianceHdr(p); }), p,
                     "16000x16000 pixels cannot fit in the rest of the file");
  p = write("gigantic.hdr", header + "-Y 100000 +X 100000\n");
  expectOneLineError(errorOf([&] { render::readRadianceHdr(p); }), p,
                     "is 100000x100000 pixels, more than the 268435456 pixels chorus reads");
  p = write("rotated.hdr", header + "+X 4 -Y 4\n");
  expectOneLineError(errorOf([&] { render::readRadianceHdr(p); }), p,
                     "resolution line '+X 4 -Y 4'");
  p = write("xyze.hdr", "#?RADIANCE\nFORMAT=32-bit_rle_xyze\n\n-Y 1 +X 1\nabcd");
  expectOneLineError(errorOf([&] { render::readRadianceHdr(p); }), p, "FORMAT=32-bit_rle_xyze");
  p = write("noheaderend.hdr", "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n");
  expectOneLineError(errorOf([&] { render::readRadianceHdr(p); }), p, "header never ends");
  p = write("png.hdr", "\x89PNG\r\n");
  expectOneLineError(errorOf([&] { render::readRadianceHdr(p); }), p, "no #? signature");
}

// Environment ----------------------------------------------------------------------------------

TEST(EnvironmentChecks, RotationAndIntensityMustBeFiniteAndInRange) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float inf = std::numeric_limits<float>::infinity();
  render::EnvironmentDesc e = render::EnvironmentDesc::constant(render::Rgb(1.0f));
  EXPECT_EQ(errorOf([&] { render::checkEnvironment(e); }), "");
  e.rotationDegrees = 720.0f;
  EXPECT_EQ(errorOf([&] { render::checkEnvironment(e); }), "");
  for (float rotation : {nan, inf, -inf}) {
    e.rotationDegrees = rotation;
    EXPECT_NE(
        errorOf([&] { render::checkEnvironment(e); }).find("is not a finite number of degrees"),
        std::string::npos);
  }
  e.rotationDegrees = 0;
  for (float intensity : {nan, inf, -1.0f, 2e9f}) {
    e.intensity = intensity;
    EXPECT_NE(errorOf([&] { render::checkEnvironment(e); }).find("must lie in [0, 1e+09]"),
              std::string::npos)
        << intensity;
  }
  e.intensity = 1;
  e.radiance = render::Rgb(1.0f, nan, 1.0f);
  EXPECT_NE(errorOf([&] { render::checkEnvironment(e); }).find("environment radiance nan"),
            std::string::npos);

  // The library entry points check before any work: the map is not read, the scene not built.
  EXPECT_NE(errorOf([&] {
              render::environmentFromFile(input("env-valid-rle.hdr"), nan);
            }).find("environment rotation nan"),
            std::string::npos);
  render::EnvironmentDesc black = render::EnvironmentDesc::constant(render::Rgb(1.0f));
  black.intensity = nan;
  EXPECT_NE(errorOf([&] {
              render::buildScene(
                  render::loadGltf(test::sourceDir() / "scenes" / "cornell-box.gltf"), black);
            }).find("environment intensity nan"),
            std::string::npos);
}

TEST(EnvironmentChecks, CliRejectsNonFiniteRotationAndIntensity) {
  TempDir dir;
  const std::string scene = (test::sourceDir() / "scenes" / "cornell-box.gltf").string();
  const std::string env = input("env-valid-rle.hdr").string();
  const auto render = [&](const std::string& env, const std::vector<std::string>& extra) {
    std::vector<std::string> args = {
        "render",    scene,      "--env",   env,     "--width",
        "8",         "--height", "8",       "--spp", "1",
        "--denoise", "none",     "--quiet", "--out", (dir / "out").string()};
    args.insert(args.end(), extra.begin(), extra.end());
    return runChorus(args);
  };
  for (const char* value : {"nan", "inf", "-inf"}) {
    SCOPED_TRACE(value);
    expectCliError(render(env, {"--env-rotate", value}), "", "rotat");
  }
  expectCliError(render(env, {"--env-intensity", "nan"}), "", "intensity");
  EXPECT_FALSE(fs::exists(dir / "out" / "render.exr"));
  for (const char* file : {"env-truncated-rle.hdr", "env-zero-length-run.hdr"})
    expectCliError(render(input(file).string(), {}), file, "");
  // A valid map renders.
  const auto ok = render(env, {"--env-rotate", "90"});
  EXPECT_EQ(ok.exitCode, 0) << ok.err;
}

// EXR ------------------------------------------------------------------------------------------

TEST(ExrLimits, HeadersClaimingHugeImagesAreRefusedBeforeAllocation) {
  const Image valid = readExrLayer(input("exr-valid-2x2.exr"));
  ASSERT_EQ(valid.width(), 2);
  EXPECT_EQ(valid.at(1, 1, 2), 0.5f);
  const struct {
    const char* file;
    const char* fragment;
  } cases[] = {
      {"exr-32768x16384-pixels.exr", "is 32768x16384 pixels, more than the 268435456 pixels"},
      {"exr-16384x16384x9-channels.exr",
       "is 16384x16384 pixels of 9 channels, more than the 2147483648 values"},
      {"exr-data-window-full-int.exr", "cannot read EXR"},
  };
  for (const auto& c : cases) {
    const fs::path path = input(c.file);
    expectOneLineError(errorOf([&] { readExr(path); }), path, c.fragment);
  }
}

// Tungsten buffer directories --------------------------------------------------------------------

TEST(TungstenMeta, SppMustBeAWholePositiveNumber) {
  TempDir dir;
  for (Quantity q : kAllQuantities) {
    const std::string name(quantityName(q));
    for (const char* suffix : {".exr", "A.exr", "B.exr", "Variance.exr"})
      writeExr(dir / (name + suffix), Image(2, 2, channelCount(q), 1.0f), ExrPixelType::Half);
  }
  const fs::path meta = dir / "meta.json";
  std::ofstream(meta) << R"({"spp": 16})";
  EXPECT_EQ(readTungstenDirectory(dir.path()).whole.sampleCount.at(1, 1, 0), 16.0f);
  for (const char* spp : {"-5", "0", "2.5", "1e30", "\"16\"", "null"}) {
    SCOPED_TRACE(spp);
    std::ofstream(meta) << R"({"scene": "x", "spp": )" << spp << "}";
    expectOneLineError(errorOf([&] { readTungstenDirectory(dir.path()); }), meta,
                       "not a whole number of samples from 1 to 16777216");
  }
  std::ofstream(meta) << R"({"extras": )" << std::string(100000, '[') << std::string(100000, ']')
                      << "}";
  expectOneLineError(errorOf([&] { readTungstenDirectory(dir.path()); }), meta,
                     "nests JSON more than 32 levels deep");
  std::ofstream(meta) << R"({"spp": )";
  expectOneLineError(errorOf([&] { readTungstenDirectory(dir.path()); }), meta, "cannot parse");
}

// The sanitizer build ---------------------------------------------------------------------------

// The lane tracer stepped −0.0f's bit pattern down as a signed integer (overflow: the
// -DCHORUS_ASAN=ON build aborted on the project's default scene). Under that build this render
// is the regression test; in a release build it checks that the lanes render the scene.
TEST(SanitizerBuild, LaneTracerRendersTheDefaultScene) {
  TempDir dir;
  const auto r = runChorus({"render", (test::sourceDir() / "scenes" / "cornell-box.gltf").string(),
                            "--tracer", "lanes", "--width", "16", "--height", "16", "--spp", "2",
                            "--denoise", "none", "--quiet", "--out", (dir / "out").string()});
  EXPECT_EQ(r.exitCode, 0) << r.err;
  EXPECT_EQ(r.err, "");
}

}  // namespace
}  // namespace chorus
