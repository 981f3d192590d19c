#include "tools/chorus/ensemble_flags.h"

#include "common/error.h"
#include "tools/chorus/flag_checks.h"

namespace chorus::cli {

void EnsembleFlags::addFlags(CLI::App& cmd) {
  cmd.add_option("--solver", solver,
                 "Weight solver: active-set (exact) or pairwise (the paper's iteration)")
      ->capture_default_str();
  cmd.add_option("--weight-filter", weightFilter,
                 "bilateral (joint bilateral on normal, albedo and the blend, radius 7) or none")
      ->capture_default_str()
      ->each([this](const std::string&) { weightFilterGiven = true; });
  cmd.add_option("--mse", mseForm,
                 "MSE matrix per-channel (one weight per colour channel) or summed (one per pixel)")
      ->capture_default_str();
  cmd.add_option("--estimate", estimate,
                 "What the MSE estimate compares: halves (each member's runs on half A and B with "
                 "the other half), quarters (its runs on three quarters with the fourth: "
                 "4 more runs per member, needs 4 sub-buffers) or extrapolated (1.5 x quarters "
                 "- 0.5 x halves)")
      ->capture_default_str();
  cmd.add_option("--window", window,
                 "Radius of the feature-guided window the MSE estimate is accumulated over "
                 "(0 = per pixel, as in the paper; default 5, and 15 where the blend takes "
                 "full runs of members that split their input: large renders at <= 16 spp)")
      ->transform(integerIn(0, kMaxWindowRadius))
      ->each([this](const std::string&) { windowGiven = true; });
  cmd.add_option("--window-color", windowColor,
                 "Colour term of that window: pixels whose mean of the members differs by more "
                 "than about S times the noisy halves' spread (or 5 %) are outside it, so that it "
                 "stops at shadow edges and caustics (0 = normals and albedo only; previews: 0 "
                 "unless given)")
      ->capture_default_str()
      ->transform(finiteIn(0, kMaxEnsembleFactor))
      ->each([this](const std::string&) { windowColorGiven = true; });
  cmd.add_flag("--relative,!--absolute", relative,
               "Divide the MSE estimate by (mean² + 0.01), each fold by its own runs' mean, so "
               "that it targets relMSE");
  cmd.add_option("--outlier-cap", outlierCap,
                 "Scale each pixel's MSE terms by F/(trace + F) before the window (trace in units "
                 "of mean|x|², or of the image's 95th-percentile trace where larger), so that a "
                 "firefly counts about as much as F in its neighbours' windows (0 = off)")
      ->capture_default_str()
      ->transform(finiteIn(0, kMaxEnsembleFactor));
  cmd.add_option("--consistency", consistency,
                 "Give a base weight 0 where its full-buffer output lies more than K times half "
                 "the A/B difference (+10%) from the mean of its half outputs (0 = off)")
      ->capture_default_str()
      ->transform(finiteIn(0, kMaxEnsembleFactor));
  cmd.add_option("--plausibility", plausibility,
                 "Give a base weight 0 where its own error term exceeds K² times the least base's "
                 "plus the noisy halves' difference (0 = off, else at least 1)")
      ->capture_default_str()
      ->transform(zeroOrFiniteIn(1, kMaxEnsembleFactor));
  cmd.add_option("--image-prior", imagePrior,
                 "Add A times the image-wide mean of the (relative) MSE terms, scaled to each "
                 "pixel's own, to the pixel's estimate: shrinkage towards the best blend over the "
                 "image (0 = off; previews: 0 unless given)")
      ->capture_default_str()
      ->transform(finiteIn(0, kMaxEnsembleFactor))
      ->each([this](const std::string&) { imagePriorGiven = true; });
  cmd.add_option("--noisy-fallback", noisyFallback,
                 "Use the noisy value where even the best base's own error term exceeds K² times "
                 "the noisy halves' difference (+10%): every base is far from both halves "
                 "(0 = off, else at least 1)")
      ->capture_default_str()
      ->transform(zeroOrFiniteIn(1, kMaxEnsembleFactor));
  cmd.add_option("--member-fallback", memberFallback,
                 "Use the member closest to the noisy data where the blend's own error term "
                 "exceeds K² times that member's plus the noise (0 = off, else at least 1; "
                 "previews: 2 unless given)")
      ->capture_default_str()
      ->transform(zeroOrFiniteIn(1, kMaxEnsembleFactor))
      ->each([this](const std::string&) { memberFallbackGiven = true; });
  cmd.add_option("--solver-seed", seed, "Seed of the pairwise solver")
      ->capture_default_str()
      ->transform(anyUnsigned64());
}

CombineOptions EnsembleFlags::options() const {
  CombineOptions o;
  o.solver = parseSolver(solver);
  if (mseForm == "per-channel")
    o.mse.form = MseForm::PerChannel;
  else if (mseForm == "summed")
    o.mse.form = MseForm::Summed;
  else
    throw Error("unknown --mse '" + mseForm + "' (known: per-channel, summed)");
  if (estimate == "halves")
    o.mse.estimate = MseEstimate::Halves;
  else if (estimate == "quarters")
    o.mse.estimate = MseEstimate::Quarters;
  else if (estimate == "extrapolated")
    o.mse.estimate = MseEstimate::Extrapolated;
  else
    throw Error("unknown --estimate '" + estimate + "' (known: halves, quarters, extrapolated)");
  // The numbers were range-checked when the flags were parsed (addFlags).
  o.mse.windowRadius = window;
  if (windowGiven) o.mse.fullRunWindowRadius = window;  // one radius everywhere
  o.mse.windowSigmaColor = float(windowColor);
  o.mse.relative = relative;
  o.mse.outlierCap = outlierCap;
  o.mse.consistency = consistency;
  o.mse.plausibility = plausibility;
  o.mse.imagePrior = imagePrior;
  o.mse.noisyFallback = noisyFallback;
  o.mse.memberFallback = memberFallback;
  if (weightFilter != "bilateral" && weightFilter != "none")
    throw Error("unknown --weight-filter '" + weightFilter + "' (known: bilateral, none)");
  o.filter.enabled = weightFilter == "bilateral";
  o.seed = seed;
  return o;
}

}  // namespace chorus::cli
