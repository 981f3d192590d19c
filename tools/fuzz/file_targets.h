#pragma once
// The in-process targets: what a case of each file format is made of, and how one is judged.
//   gltf         loadGltf, the SceneDesc's promises (indices in range, per-vertex arrays of
//                one length, valid material/texture/image references), what `chorus info`
//                reads, buildScene and an 8×8 render at 1 spp (finite buffers)
//   exr          readExr, readExrLayer, readRgbExr, sampleBuffersFromLayers; for a Tungsten
//                directory readTungstenDirectory (finite, non-negative sample counts)
//   environment  loadEnvironmentImage (texels finite and ≥ 0) and an 8×8 render of a floor
//                under the map
#include <filesystem>
#include <string>

#include "tools/fuzz/fuzz_case.h"
#include "tools/fuzz/fuzz_random.h"
#include "tools/fuzz/seed_corpus.h"

namespace chorus::fuzz {

// A mutated input of `target` (Gltf, Exr or Environment) from the seeds.
FuzzCase generateFileCase(Target target, const SeedCorpus& seeds, FuzzRandom& rng);

// Runs the case's check on the files already written into `caseDir`; meant to run in a
// sandboxed child (runInChild). Returns "" or the broken promise; throws what the code throws.
std::string checkFileCase(const FuzzCase& fuzzCase, const std::filesystem::path& caseDir);

}  // namespace chorus::fuzz
