#pragma once
// Radiance .hdr (RGBE) files for the environment-map target: a writer for flat and run-length
// encoded scanlines (the packaged stb decoder mishandles truncated RLE data, CVE-2021-42715),
// and edits that know the format: the resolution line, the FORMAT line, truncation inside the
// pixel data, broken run lengths and scanline headers.
#include <string>

#include "common/image/image.h"
#include "tools/fuzz/fuzz_random.h"

namespace chorus::fuzz {

// An RGB image as a .hdr file. `rle`: new-style run-length encoded scanlines (width 8–32767),
// otherwise flat RGBE pixels.
std::string radianceHdr(const Image& rgb, bool rle);

// Applies one .hdr-aware edit to `data` and returns what it did.
std::string mutateRadianceHdr(std::string& data, FuzzRandom& rng);

}  // namespace chorus::fuzz
