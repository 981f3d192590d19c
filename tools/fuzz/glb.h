#pragma once
// The binary glTF container (glTF 2.0 §4.4): a 12-byte header, a JSON chunk and an optional
// BIN chunk. The fuzzer builds .glb seeds with it and edits a .glb's JSON structurally.
#include <optional>
#include <string>

namespace chorus::fuzz {

struct GlbParts {
  std::string json;
  std::string bin;  // empty: no BIN chunk
};

std::string packGlb(const GlbParts& parts);
// The two chunks of a well-formed .glb, or nullopt when it is not one.
std::optional<GlbParts> unpackGlb(const std::string& bytes);

}  // namespace chorus::fuzz
