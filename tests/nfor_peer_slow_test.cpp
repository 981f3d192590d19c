// Our NFOR against the NFOR author's own implementation (Tungsten, commit 88ea020) on exactly
// the same input buffers: ../shared/peers/tungsten-nfor/{room,glossy,highlights}/spp{4,16,64}
// (skipped without ../shared). For every case:
//   relMSE(ours, reference) ≤ 1.03 × relMSE(Tungsten's nfor.exr, reference), also over the
//   pixels around highlights alone and over the rest (highlight_region.h), and
//   relMSE(ours, nfor.exr) ≤ kAgreement × relMSE(noisy input, nfor.exr): the two outputs are
//   far closer to each other than the input is to either (measured with the double-precision
//   Gram sums: ≤ 0.07 %; 0.09–1.2 % with the former float sums and pivot tolerance 1e-5).
// Dual-buffer NL-means runs on the same inputs as a sanity check: relMSE below a fifth of the
// noisy input's (measured 6–12 %).
#include <gtest/gtest.h>

#include <cstdio>
#include <vector>

#include "common/image/exr_io.h"
#include "denoise/base/nfor/nfor.h"
#include "denoise/base/nlm/dual_buffer_nlm.h"
#include "denoise/buffers/tungsten_dir.h"
#include "denoise/metrics/metrics.h"
#include "tests/support/denoiser_checks.h"
#include "tests/support/highlight_region.h"
#include "tests/support/test_support.h"

namespace chorus {
namespace {

constexpr double kMaxRatioToTungsten = 1.03;
constexpr double kAgreement = 0.003;

TEST(NforPeer, MatchesTungstenOnAllNineCases) {
  CHORUS_REQUIRE_SHARED(shared);
  const auto root = shared / "peers/tungsten-nfor";
  std::printf("%-10s %-6s %12s %12s %7s %14s %14s %7s %12s %9s %9s\n", "scene", "spp",
              "relMSE ours", "tungsten", "ratio", "ours-vs-tung", "noisy-vs-tung", "frac",
              "relMSE nlm", "hl ratio", "rest");
  for (const char* scene : {"room", "glossy", "highlights"}) {
    const Image reference = readExrLayer(root / scene / "reference.exr");
    const std::vector<bool> highlights = test::highlightMask(reference);
    for (const char* spp : {"spp4", "spp16", "spp64"}) {
      const auto dir = root / scene / spp;
      const DenoiseInput input = readTungstenDirectory(dir);
      const Image tungsten = readExrLayer(dir / "nfor.exr");
      const Image ours = NforDenoiser().run(input);
      const Image nlm = DualBufferNlMeans().run(input);
      ASSERT_EQ(test::firstNonFinite(ours), "") << scene << " " << spp;
      ASSERT_EQ(test::firstNonFinite(nlm), "") << scene << " " << spp;
      const double oursRef = relMse(ours, reference), tungRef = relMse(tungsten, reference);
      const double agreement = relMse(ours, tungsten);
      const double noisyTung = relMse(input.whole.color.mean, tungsten);
      const double nlmRef = relMse(nlm, reference);
      double part[2][2];  // [ours, tungsten][rest, highlights]
      for (int inside = 0; inside < 2; ++inside) {
        part[0][inside] = test::relMsePart(ours, reference, highlights, inside == 1);
        part[1][inside] = test::relMsePart(tungsten, reference, highlights, inside == 1);
      }
      std::printf("%-10s %-6s %12.6f %12.6f %7.4f %14.3e %14.3e %7.4f %12.6f %9.4f %9.4f\n", scene,
                  spp, oursRef, tungRef, oursRef / tungRef, agreement, noisyTung,
                  agreement / noisyTung, nlmRef, part[0][1] / part[1][1], part[0][0] / part[1][0]);
      EXPECT_LE(oursRef, kMaxRatioToTungsten * tungRef) << scene << " " << spp;
      EXPECT_LE(part[0][1], kMaxRatioToTungsten * part[1][1])
          << scene << " " << spp << " highlights";
      EXPECT_LE(part[0][0], kMaxRatioToTungsten * part[1][0]) << scene << " " << spp << " rest";
      EXPECT_LE(agreement, kAgreement * noisyTung) << scene << " " << spp;
      EXPECT_LT(nlmRef, 0.2 * relMse(input.whole.color.mean, reference)) << scene << " " << spp;
    }
  }
}

}  // namespace
}  // namespace chorus
