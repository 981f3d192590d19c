#pragma once
// Reads the buffer directory Tungsten's renderer writes for its denoiser (and that the NFOR peer
// data in ../shared/peers/tungsten-nfor uses): for T in color, albedo, normal, depth, visibility
// the files T.exr (mean of all samples), TA.exr / TB.exr (means of the even / odd samples) and
// TVariance.exr (variance of the mean over all samples; NaN where T had no sample). Colour,
// albedo and normal have channels R G B, depth and visibility Y; usually half float.
#include <filesystem>

#include "denoise/buffers/sample_buffers.h"

namespace chorus {

// True when `dir` looks like a Tungsten buffer directory (color.exr, colorA.exr, colorB.exr and
// colorVariance.exr exist).
bool isTungstenDirectory(const std::filesystem::path& dir);

// whole = T / TVariance; halves = TA / TB. Tungsten does not store per-half variances: each
// half's variance of the mean is taken as 2 × TVariance (equal sample counts), which is what
// Tungsten's NFOR assumes too. Sample counts come from meta.json's "spp" when present
// (whole = spp, halves = spp / 2; anything but a whole number from 1 to 2^24 is an error),
// otherwise they are 0 ("unknown"). Missing feature files are
// errors; files of a different size are errors naming the file.
DenoiseInput readTungstenDirectory(const std::filesystem::path& dir);

}  // namespace chorus
