#pragma once
// Radiance RGBE images (.hdr, .pic), decoded here instead of by stb_image: the packaged stb
// loops forever on a file truncated inside its run-length scanlines (CVE-2021-42715), and on
// a run of length 0 anywhere. Every read here is bounded by the bytes present, and a file stb
// decodes correctly gives the same floats bit for bit (tests/loader_hardening_test.cpp).
//
// Accepted: a "#?" header with FORMAT=32-bit_rle_rgbe, the resolution line "-Y H +X W", then
// either flat 4-byte pixels or one new-style run-length scanline per row (widths 8 … 32767,
// as writers emit them).
#include <filesystem>

#include "common/image/image.h"

namespace chorus::render {

// Linear RGB, 3 channels. Throws chorus::Error naming the file for anything malformed,
// truncated or beyond common/image/image_limits.h.
Image readRadianceHdr(const std::filesystem::path& path);

}  // namespace chorus::render
