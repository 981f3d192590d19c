#pragma once
// Edits of an OpenEXR file that know its layout (magic, version, header attributes, line offset
// table, chunk headers): one integer field — a data or display window corner, a channel's pixel
// type or sampling, the compression, an attribute's size, the version flags, an offset table
// entry, a chunk's line number or data size — set to a value at the edge of its range.
#include <string>

#include "tools/fuzz/fuzz_random.h"

namespace chorus::fuzz {

// Applies one such edit to `data` (a scanline EXR as writeExr writes it) and returns what it
// did; falls back to a byte-level edit when the header cannot be parsed.
std::string mutateExrFields(std::string& data, FuzzRandom& rng);

}  // namespace chorus::fuzz
