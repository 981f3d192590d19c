// chorus compare IMAGE REFERENCE: every metric of denoise/metrics, as text or JSON.
#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdio>
#include <iostream>

#include "common/error.h"
#include "common/image/exr_io.h"
#include "common/image/finite_pixels.h"
#include "denoise/metrics/metrics.h"
#include "tools/chorus/command.h"

namespace chorus::cli {
namespace {

struct CompareArgs {
  std::string image, reference, layer;
  bool json = false;
};

// The RGB channels of a layer (1-channel layers are compared as they are).
Image rgbLayer(const std::string& path, const std::string& layer) {
  Image image = readExrLayer(path, layer);
  if (image.channels() == 4) return image.channelRange(0, 3);
  return image;
}

void runCompare(const CompareArgs& args) {
  const Image image = rgbLayer(args.image, args.layer);
  const Image reference = rgbLayer(args.reference, args.layer);
  if (!image.sameShape(reference))
    throw fileError(args.image, "is " + std::to_string(image.width()) + "x" +
                                    std::to_string(image.height()) + "x" +
                                    std::to_string(image.channels()) + " but " + args.reference +
                                    " is " + std::to_string(reference.width()) + "x" +
                                    std::to_string(reference.height()) + "x" +
                                    std::to_string(reference.channels()));
  // One NaN would turn every metric into NaN: refuse rather than print nulls.
  requireFinitePixels(image, args.image);
  requireFinitePixels(reference, args.reference);
  const ImageMetrics m = computeMetrics(image, reference);
  if (args.json) {
    nlohmann::ordered_json j;
    j["image"] = args.image;
    j["reference"] = args.reference;
    j["layer"] = args.layer;
    j["width"] = image.width();
    j["height"] = image.height();
    j["channels"] = image.channels();
    j["mse"] = m.mse;
    j["relmse"] = m.relMse;
    // JSON has no infinity: identical images report psnr null.
    j["psnr"] = std::isfinite(m.psnr) ? nlohmann::ordered_json(m.psnr) : nlohmann::ordered_json();
    j["ssim"] = m.ssim;
    j["dssim"] = m.dssim;
    j["smape"] = m.smape;
    std::cout << j.dump(2) << "\n";
    return;
  }
  std::printf("image      %s\nreference  %s\nlayer      %s\nsize       %dx%dx%d\n",
              args.image.c_str(), args.reference.c_str(),
              args.layer.empty() ? "<default>" : args.layer.c_str(), image.width(), image.height(),
              image.channels());
  std::printf(
      "mse        %.6g\nrelmse     %.6g   (eps 0.01)\npsnr       %.4f dB (linear, peak 1)\n"
      "ssim       %.6f (on clamp(v,0,1)^(1/2.2))\ndssim      %.6g\nsmape      %.6g\n",
      m.mse, m.relMse, m.psnr, m.ssim, m.dssim, m.smape);
}

const RegisterCommand compareCommand(10, [](CLI::App& app) {
  auto args = std::make_shared<CompareArgs>();
  CLI::App* cmd = app.add_subcommand(
      "compare",
      "Print error metrics (MSE, relMSE, PSNR, SSIM, DSSIM, SMAPE) of an EXR image "
      "against a reference EXR");
  cmd->add_option("image", args->image, "Image to evaluate (.exr)")->required();
  cmd->add_option("reference", args->reference, "Reference image (.exr)")->required();
  cmd->add_option("--layer", args->layer,
                  "Layer to compare in both files (default: the unnamed RGB layer)");
  cmd->add_flag("--json", args->json, "Print one JSON object instead of text");
  cmd->callback([args] { runCompare(*args); });
});

}  // namespace
}  // namespace chorus::cli
