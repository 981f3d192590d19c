#pragma once
// The valid inputs every mutation starts from: the project's scenes (scenes/*.gltf with their
// buffers and textures), small glTF files built here (a data-URI triangle with a camera and a
// point light; quantized positions, a sparse accessor, a strip, a data-URI PNG texture, an
// orthographic camera; the Cornell box packed as .glb), EXRs written by chorus's own writer
// (float RGB, half RGBA, one channel, a K = 2 render.exr, a Tungsten buffer directory with
// meta.json), and environment maps (flat and run-length encoded .hdr, half .exr).
#include <filesystem>
#include <string>
#include <vector>

#include "tools/fuzz/fuzz_case.h"

namespace chorus::fuzz {

struct SeedInput {
  std::string name;             // for reports
  std::vector<CaseFile> files;  // files[0] is the main input (for a Tungsten directory: all)
  bool directory = false;       // the input is the directory holding the files
};

struct SeedCorpus {
  std::vector<SeedInput> gltf, exr, environment;
};

// Builds the seed files under `dir` (in a child process, since the EXR writer starts a thread
// pool that a forked case must not inherit) and reads them back. Throws chorus::Error.
SeedCorpus buildSeedCorpus(const std::filesystem::path& sourceDir,
                           const std::filesystem::path& dir);

}  // namespace chorus::fuzz
