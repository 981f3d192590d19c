#include "common/image/exr_io.h"

#include <Imath/half.h>
#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <ImfOutputFile.h>
#include <ImfTestFile.h>
#include <ImfThreading.h>

#include <algorithm>
#include <fstream>
#include <map>
#include <thread>

#include "common/atomic_file.h"
#include "common/error.h"
#include "common/image/image_limits.h"
#include "common/regular_file.h"

namespace chorus {
namespace fs = std::filesystem;

namespace {

// OpenEXR compresses and decompresses blocks of lines on its own thread pool, which is empty
// until sized: writing a 512², K = 4 render.exr took 1.6 s on one thread. Sized once, to the
// machine. Also once: the largest image and tile sizes OpenEXR opens, so that a header claiming
// 2^31 rows is refused before OpenEXR allocates its tables for them (tiles beyond 8192² exist
// in no real file).
int exrThreads() {
  static const int threads = [] {
    const int n = int(std::max(1u, std::thread::hardware_concurrency()));
    Imf::setGlobalThreadCount(n);
    Imf::Header::setMaxImageSize(int(kMaxImagePixels), int(kMaxImagePixels));
    Imf::Header::setMaxTileSize(8192, 8192);
    return n;
  }();
  return threads;
}

std::vector<std::string> suffixesFor(int channels) {
  switch (channels) {
    case 1:
      return {"Y"};
    case 2:
      return {"X", "Y"};
    case 3:
      return {"R", "G", "B"};
    case 4:
      return {"R", "G", "B", "A"};
    default: {
      std::vector<std::string> s;
      for (int c = 0; c < channels; ++c) s.push_back(std::to_string(c));
      return s;
    }
  }
}

std::string channelName(const std::string& layer, const std::string& suffix) {
  return layer.empty() ? suffix : layer + "." + suffix;
}

// Sort key that puts a layer's channels in their conventional order (R G B A, X Y Z, Y, then
// anything else alphabetically) instead of EXR's alphabetical order (B G R).
int suffixRank(const std::string& suffix) {
  static const std::map<std::string, int> ranks = {{"R", 0}, {"r", 0}, {"X", 0}, {"x", 0}, {"G", 1},
                                                   {"g", 1}, {"Y", 1}, {"y", 1}, {"B", 2}, {"b", 2},
                                                   {"Z", 2}, {"z", 2}, {"A", 3}, {"a", 3}};
  auto it = ranks.find(suffix);
  if (it != ranks.end()) return it->second;
  // Numeric suffixes keep their numeric order after the named ones.
  if (!suffix.empty() && std::all_of(suffix.begin(), suffix.end(), ::isdigit))
    return 10 + std::stoi(suffix.substr(0, 6));
  return 1000;
}

void checkIsExr(const fs::path& path) {
  requireRegularFile(path);
  std::ifstream in(path, std::ios::binary);
  unsigned char magic[4] = {0, 0, 0, 0};
  in.read(reinterpret_cast<char*>(magic), 4);
  if (!in) throw fileError(path, "not an OpenEXR file (too short)");
  if (!(magic[0] == 0x76 && magic[1] == 0x2f && magic[2] == 0x31 && magic[3] == 0x01))
    throw fileError(path, "not an OpenEXR file");
}

}  // namespace

const ExrLayer* findLayer(const std::vector<ExrLayer>& layers, const std::string& name) {
  for (const ExrLayer& layer : layers)
    if (layer.name == name) return &layer;
  return nullptr;
}

void writeExr(const fs::path& path, const std::vector<ExrLayer>& layers, ExrPixelType type) {
  if (layers.empty()) throw fileError(path, "nothing to write (no layers)");
  const int width = layers[0].image.width(), height = layers[0].image.height();
  if (width <= 0 || height <= 0) throw fileError(path, "cannot write an empty image");
  for (const ExrLayer& layer : layers)
    if (layer.image.width() != width || layer.image.height() != height)
      throw fileError(path, "layer '" + layer.name + "' differs in size from the others");

  const Imf::PixelType pixelType = type == ExrPixelType::Half ? Imf::HALF : Imf::FLOAT;
  writeAtomically(path, [&](const fs::path& tmp) {
    Imf::Header header(width, height);
    header.compression() = Imf::ZIP_COMPRESSION;
    // Level 1: a render.exr of noisy floats shrinks about as much as at the default level (24.9
    // against 24.3 MB for 512², K = 4) in three quarters of the time.
    header.zipCompressionLevel() = 1;
    Imf::FrameBuffer frame;
    // OpenEXR does not convert float to half on output: half layers are converted here.
    std::vector<std::vector<half>> halfCopies;
    halfCopies.reserve(layers.size());
    for (const ExrLayer& layer : layers) {
      const std::vector<std::string> suffixes = suffixesFor(layer.image.channels());
      const size_t channels = size_t(layer.image.channels());
      char* base = reinterpret_cast<char*>(const_cast<float*>(layer.image.data()));
      size_t elementSize = sizeof(float);
      if (type == ExrPixelType::Half) {
        halfCopies.emplace_back(layer.image.values().begin(), layer.image.values().end());
        base = reinterpret_cast<char*>(halfCopies.back().data());
        elementSize = sizeof(half);
      }
      const size_t pixelStride = elementSize * channels;
      for (size_t c = 0; c < channels; ++c) {
        const std::string name = channelName(layer.name, suffixes[c]);
        if (header.channels().findChannel(name))
          throw fileError(path, "channel '" + name + "' would be written twice");
        header.channels().insert(name, Imf::Channel(pixelType));
        frame.insert(name, Imf::Slice(pixelType, base + c * elementSize, pixelStride,
                                      pixelStride * size_t(width)));
      }
    }
    try {
      Imf::OutputFile file(tmp.c_str(), header, exrThreads());
      file.setFrameBuffer(frame);
      file.writePixels(height);
    } catch (const std::exception& e) {
      throw fileError(path, std::string("cannot write EXR: ") + e.what());
    }
  });
}

void writeExr(const fs::path& path, const Image& image, ExrPixelType type) {
  writeExr(path, std::vector<ExrLayer>{{"", image}}, type);
}

std::vector<ExrLayer> readExr(const fs::path& path) {
  checkIsExr(path);
  try {
    Imf::InputFile file(path.c_str(), exrThreads());
    const Imath::Box2i window = file.header().dataWindow();
    // 64-bit: a data window from INT_MIN to INT_MAX is 2^32 wide.
    const int64_t width = int64_t(window.max.x) - int64_t(window.min.x) + 1;
    const int64_t height = int64_t(window.max.y) - int64_t(window.min.y) + 1;
    int64_t channelCount = 0;
    for (auto it = file.header().channels().begin(); it != file.header().channels().end(); ++it)
      ++channelCount;
    if (width <= 0 || height <= 0) throw fileError(path, "empty data window");
    if (const std::string problem = imageSizeProblem(width, height, channelCount); !problem.empty())
      throw fileError(path, problem);

    // Group channels into layers by the part before the last dot.
    std::vector<std::string> layerOrder;
    std::map<std::string, std::vector<std::string>> suffixes;
    const Imf::ChannelList& channels = file.header().channels();
    for (auto it = channels.begin(); it != channels.end(); ++it) {
      const std::string name = it.name();
      const size_t dot = name.rfind('.');
      const std::string layer = dot == std::string::npos ? "" : name.substr(0, dot);
      const std::string suffix = dot == std::string::npos ? name : name.substr(dot + 1);
      if (it.channel().xSampling != 1 || it.channel().ySampling != 1)
        throw fileError(path, "channel '" + name + "' is subsampled (not supported)");
      if (!suffixes.count(layer)) layerOrder.push_back(layer);
      suffixes[layer].push_back(suffix);
    }
    if (layerOrder.empty()) throw fileError(path, "no channels");
    // The default layer first, as viewers show it.
    std::stable_sort(
        layerOrder.begin(), layerOrder.end(),
        [](const std::string& a, const std::string& b) { return a.empty() && !b.empty(); });

    std::vector<ExrLayer> layers;
    Imf::FrameBuffer frame;
    layers.reserve(layerOrder.size());
    for (const std::string& layerName : layerOrder) {
      std::vector<std::string>& names = suffixes[layerName];
      std::stable_sort(names.begin(), names.end(), [](const std::string& a, const std::string& b) {
        const int ra = suffixRank(a), rb = suffixRank(b);
        return ra != rb ? ra < rb : a < b;
      });
      layers.push_back({layerName, Image(int(width), int(height), int(names.size()))});
      Image& image = layers.back().image;
      const size_t pixelStride = sizeof(float) * size_t(image.channels());
      // Slice::Make places the data window's corner on pixel (0, 0).
      for (size_t c = 0; c < names.size(); ++c)
        frame.insert(channelName(layerName, names[c]),
                     Imf::Slice::Make(Imf::FLOAT, image.data() + c, window, pixelStride,
                                      pixelStride * size_t(width)));
    }
    file.setFrameBuffer(frame);
    file.readPixels(window.min.y, window.max.y);
    return layers;
  } catch (const Error&) {
    throw;
  } catch (const std::exception& e) {
    std::string what = e.what();
    if (const size_t nl = what.find('\n'); nl != std::string::npos) what.resize(nl);
    throw fileError(path, "cannot read EXR: " + what);
  }
}

Image readExrLayer(const fs::path& path, const std::string& name) {
  std::vector<ExrLayer> layers = readExr(path);
  for (ExrLayer& layer : layers)
    if (layer.name == name) return std::move(layer.image);
  if (name.empty() && layers.size() == 1) return std::move(layers[0].image);
  std::string available;
  for (const ExrLayer& layer : layers)
    available += (available.empty() ? "" : ", ") + (layer.name.empty() ? "<default>" : layer.name);
  throw fileError(
      path, "no layer '" + (name.empty() ? "<default>" : name) + "' (layers: " + available + ")");
}

Image readRgbExr(const fs::path& path) {
  Image image = readExrLayer(path);
  if (image.channels() == 4) image = image.channelRange(0, 3);
  if (image.channels() != 3)
    throw fileError(path, "has " + std::to_string(image.channels()) + " channels, expected RGB");
  return image;
}

}  // namespace chorus
