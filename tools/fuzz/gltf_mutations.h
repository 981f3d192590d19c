#pragma once
// Structure-aware edits of a glTF JSON document: numbers replaced by extremes (−1, 0, 2^31,
// 2^32, 2^62, 2^63, (2^64+2)/3, 2^64, 1e20, 1e-30, 1e309, NaN-like text, wrong JSON types),
// fields a loader must check set to such values (accessor counts, offsets and strides, buffer
// lengths, camera parameters, node transforms, …), keys deleted or duplicated, array elements
// deleted, duplicated or appended, values nested thousands deep, indices pointed at the wrong
// object, node children made cyclic or a deep DAG, buffer and image URIs replaced by bad ones
// (directories, devices, FIFOs, malformed data URIs), cameras added far away.
//
// Literals JSON cannot hold (2^64, NaN, 100 000 nested arrays) are kept as placeholders in the
// document and spliced into the text only by text(), so that the driver never walks or parses
// a hostile document itself.
#include <nlohmann/json.hpp>

#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "tools/fuzz/fuzz_random.h"

namespace chorus::fuzz {

class GltfEditor {
 public:
  explicit GltfEditor(nlohmann::json document) : doc_(std::move(document)) {}

  // Applies one random edit; returns what it did, e.g. "accessors/3/count = 4294967296".
  std::string randomEdit(FuzzRandom& rng);
  // The edited document as text, placeholders replaced by their literals.
  std::string text() const;
  // Named pipes the edits made URIs point at (the case must create them).
  const std::vector<std::string>& fifos() const { return fifos_; }

  // The individual edits (public so that regression inputs can be built from them).
  std::string extremeNumber(FuzzRandom& rng);
  std::string targetedField(FuzzRandom& rng);
  std::string deleteKey(FuzzRandom& rng);
  std::string duplicateKey(FuzzRandom& rng);
  std::string editArray(FuzzRandom& rng);
  std::string deepNesting(FuzzRandom& rng);
  std::string crossIndex(FuzzRandom& rng);
  std::string cyclicChildren(FuzzRandom& rng);
  std::string nodeDag(FuzzRandom& rng);
  std::string badUri(FuzzRandom& rng);
  std::string farCamera(FuzzRandom& rng);

 private:
  // A string that text() replaces, quotes included, by `literal`.
  std::string placeholder(std::string literal);
  nlohmann::json randomValue(FuzzRandom& rng, const std::string& key);
  // A random key of a random non-empty object (up to 8 tries), with the object's pointer.
  std::optional<std::pair<nlohmann::json::json_pointer, std::string>> pickKey(
      FuzzRandom& rng) const;

  nlohmann::json doc_;
  std::vector<std::pair<std::string, std::string>> literals_;  // placeholder → literal
  std::vector<std::string> fifos_;
};

// The literal numbers (and number-like text) the edits use.
const std::vector<std::string>& extremeLiterals();

}  // namespace chorus::fuzz
