// Chooses the ensemble's default options by measurement: for every documented synthetic case
// (tests/support/synthetic_cases.h) runs each combiner and each MSE option variant and prints
// relMSE tables — per variant, the geometric mean of relMSE over the cases and how often it
// beats the best single base output — then the same for every combiner at the default options.
// Never run by CTest.
#include <tbb/global_control.h>
#include <CLI/CLI.hpp>

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "denoise/ensemble/combiners.h"
#include "denoise/metrics/metrics.h"
#include "tests/support/synthetic_cases.h"

namespace {
using namespace chorus;

struct Variant {
  std::string name;
  CombineOptions options;
};

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"relMSE of ensemble option variants on the synthetic cases"};
  int size = 96, threads = 2;
  bool quick = false;
  std::vector<int> radii = {0, 1, 2, 3, 5};
  app.add_option("--size", size, "image width and height");
  app.add_option("--threads", threads, "TBB threads");
  app.add_flag("--quick", quick, "only the MSE-form variants");
  app.add_option("--radii", radii, "MSE window radii to compare");
  CLI11_PARSE(app, argc, argv);
  tbb::global_control limit(tbb::global_control::max_allowed_parallelism, size_t(threads));

  std::vector<Variant> variants;
  for (MseForm form : {MseForm::PerChannel, MseForm::Summed})
    for (int radius : radii)
      for (bool relative : {false, true})
        for (bool normalize : {false, true})
          for (bool filter : {true, false}) {
            if ((quick && !filter) || (normalize && radius == 0)) continue;  // r = 0: same argmin
            Variant v;
            v.options.mse.form = form;
            v.options.mse.windowRadius = radius;
            v.options.mse.relative = relative;
            v.options.mse.outlierCap = normalize ? MseOptions{}.outlierCap : 0.0;
            v.options.filter.enabled = filter;
            v.name = std::string(form == MseForm::PerChannel ? "per-channel" : "summed") +
                     " r=" + std::to_string(radius) + (relative ? " relative" : " absolute") +
                     (normalize ? " capped" : "") + (filter ? " filter" : " nofilter");
            variants.push_back(v);
          }

  const std::vector<synthetic::Case> cases = synthetic::standardCases();
  // Then every combiner with the default options (the oracle against the truth).
  const size_t firstCombiner = variants.size();
  for (Combiner c : {Combiner::Ensemble, Combiner::Average, Combiner::OnehotPre,
                     Combiner::OnehotPost, Combiner::Oracle}) {
    Variant v;
    v.options.combiner = c;
    v.name = "combiner " + std::string(combinerName(c)) + " (defaults)";
    variants.push_back(v);
  }
  std::vector<double> logSum(variants.size(), 0.0);
  std::vector<int> wins(variants.size(), 0);
  double logBest = 0;
  std::printf("%-28s %10s", "case", "best base");
  std::printf("\n");
  std::vector<std::vector<double>> table(cases.size());
  for (size_t ci = 0; ci < cases.size(); ++ci) {
    const synthetic::PreparedCase prepared = synthetic::prepareCase(cases[ci], size, size);
    const auto bases = pointersTo(prepared.bases);
    double best = 1e300;
    for (const BaseOutputs& base : prepared.bases)
      best = std::min(best, relMse(base.full, prepared.truth));
    logBest += std::log(best);
    std::printf("%-28s %10.5f", cases[ci].name.c_str(), best);
    for (size_t vi = 0; vi < variants.size(); ++vi) {
      const double value =
          relMse(combine(prepared.guides, bases, variants[vi].options, &prepared.truth).image,
                 prepared.truth);
      logSum[vi] += std::log(value);
      wins[vi] += value < best;
      std::printf(" %.5f", value);
    }
    std::printf("\n");
  }
  std::printf("\n%-50s %12s %8s\n", "variant", "geomean relMSE", "wins");
  std::printf("%-50s %12.6f\n", "best single base (per case)", std::exp(logBest / cases.size()));
  for (size_t vi = 0; vi < variants.size(); ++vi)
    std::printf("%s%-50s %12.6f %5d/%zu\n", vi == firstCombiner ? "\n" : "",
                variants[vi].name.c_str(), std::exp(logSum[vi] / cases.size()), wins[vi],
                cases.size());
  return 0;
}
