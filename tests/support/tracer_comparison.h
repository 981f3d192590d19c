#pragma once
// The lane tracer against the one-path tracer on one scene (tests of LaneTracer).
#include "renderer/render.h"

namespace chorus::test {

// Renders `scene` with both tracers (options.tracer is overridden) and expects the same buffers
// bit for bit — mean and variance of every quantity of every sub-buffer, and the emission plane
// when options.separateEmission — and the same ray and dropped-sample counts. Returns the one-path
// render's mean colour over sub-buffer 0, so that a caller can check the comparison was not between
// two black images.
double expectTracersAgree(const render::Scene& scene, render::RenderOptions options);

}  // namespace chorus::test
