#include "denoise/pipeline/member_planes.h"

#include <map>

#include "common/error.h"

namespace chorus {

namespace {

BufferPlanes means(std::initializer_list<Quantity> quantities) {
  BufferPlanes planes = BufferPlanes::colorOnly();
  for (Quantity q : quantities) planes = planes.with(q, Plane::Mean);
  return planes;
}

BufferPlanes meansAndVariances(std::initializer_list<Quantity> quantities) {
  BufferPlanes planes = BufferPlanes::colorOnly();
  for (Quantity q : quantities) planes = planes.with(q, Plane::Variance);
  return planes;
}

// From each member's source (denoise/base/<family>/); member_planes_test checks every entry: the
// planes left out do not change the member's output.
const std::map<std::string, BufferPlanes>& readByName() {
  using enum Quantity;
  static const std::map<std::string, BufferPlanes> table = {
      {"nfor", BufferPlanes::all()},  // Tungsten's four features, means and variances
      {"rdfc", BufferPlanes::all()},  // the same four, prefiltered with their variances
      {"nlm", BufferPlanes::colorOnly()},
      {"atrous", means({Albedo, Normal, Depth})},  // edge-stopping on feature means only
      // Cross-bilateral range terms: each feature's per-sample variance.
      {"bilateral", meansAndVariances({Albedo, Normal, Depth})},
      {"sbf", meansAndVariances({Albedo, Normal, Depth})},
      {"jnlm", meansAndVariances({Albedo, Normal, Depth})},
  };
  return table;
}

// The combination's guides (EnsembleGuides): the full buffer's albedo and normal means.
BufferPlanes combinationPlanes() {
  return means({Quantity::Albedo, Quantity::Normal});
}

}  // namespace

BufferPlanes planesReadBy(const BaseDenoiser& denoiser) {
  const auto& table = readByName();
  const auto it = table.find(denoiser.name());
  return it != table.end() ? it->second : BufferPlanes::all();
}

BufferPlanes planesReadBy(std::span<const EnsembleMember> members, bool combined) {
  BufferPlanes planes = combined ? combinationPlanes() : BufferPlanes::colorOnly();
  for (const EnsembleMember& member : members) planes = planes | planesReadBy(*member.denoiser);
  return planes;
}

void checkPlanesHeld(BufferPlanes held, std::span<const EnsembleMember> members, bool combined) {
  for (const EnsembleMember& member : members) {
    const BufferPlanes read = planesReadBy(*member.denoiser);
    if (!held.contains(read))
      throw Error("base denoiser '" + member.label + "' reads " + read.minus(held).list() +
                  ", which the input does not hold");
  }
  if (combined && !held.contains(combinationPlanes()))
    throw Error("the combination reads " + combinationPlanes().minus(held).list() +
                ", which the input does not hold");
}

}  // namespace chorus
