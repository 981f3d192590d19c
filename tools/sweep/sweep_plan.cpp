#include "tools/sweep/sweep_plan.h"

#include <algorithm>
#include <bit>
#include <charconv>
#include <map>
#include <sstream>

#include "common/error.h"
#include "tools/sweep/sweep_results.h"

namespace chorus::sweep {

std::string SweepCase::fileStem() const {
  return scene + "_spp" + std::to_string(spp);
}

std::vector<SweepCase> planCases(const std::vector<std::filesystem::path>& scenes,
                                 const std::vector<int>& spps) {
  std::map<std::string, int> stemUses;
  for (const auto& path : scenes) ++stemUses[path.stem().string()];
  std::vector<int> sorted = spps;
  std::sort(sorted.begin(), sorted.end());
  sorted.erase(std::unique(sorted.begin(), sorted.end()), sorted.end());
  std::vector<SweepCase> cases;
  for (const auto& path : scenes) {
    std::string name = path.stem().string();
    if (stemUses[name] > 1) name = path.parent_path().filename().string() + "-" + name;
    for (int spp : sorted) cases.push_back({path, name, spp});
  }
  return cases;
}

Shard parseShard(const std::string& text) {
  Shard shard;
  const size_t slash = text.find('/');
  auto parse = [&](const std::string& part, int& out) {
    const auto [end, ec] = std::from_chars(part.data(), part.data() + part.size(), out);
    return ec == std::errc() && end == part.data() + part.size();
  };
  if (slash == std::string::npos || !parse(text.substr(0, slash), shard.index) ||
      !parse(text.substr(slash + 1), shard.count) || shard.count < 1 || shard.index < 0 ||
      shard.index >= shard.count)
    throw Error("--shard '" + text + "' must be I/N with 0 <= I < N");
  return shard;
}

std::vector<SweepCase> casesOfShard(const std::vector<SweepCase>& cases, Shard shard) {
  std::vector<SweepCase> mine;
  for (size_t i = 0; i < cases.size(); ++i)
    if (int(i % size_t(shard.count)) == shard.index) mine.push_back(cases[i]);
  return mine;
}

std::vector<std::string> planCombinations(const std::vector<std::string>& methods,
                                          const std::string& spec) {
  const int n = int(methods.size());
  std::vector<std::string> combos;
  auto join = [&](const std::vector<int>& indices) {
    std::string name;
    for (int i : indices) name += (name.empty() ? "" : "+") + methods[size_t(i)];
    return name;
  };
  if (spec == "all") {
    if (n > 16) throw Error("--combos all: too many methods (" + std::to_string(n) + " > 16)");
    for (int size = 2; size <= n; ++size)
      for (uint32_t mask = 0; mask < (1u << n); ++mask) {
        if (std::popcount(mask) != size) continue;
        std::vector<int> indices;
        for (int i = 0; i < n; ++i)
          if (mask & (1u << i)) indices.push_back(i);
        combos.push_back(join(indices));
      }
    // Within a size, order lexicographically by member positions (a+b before a+c before b+c).
    std::stable_sort(combos.begin(), combos.end(), [&](const std::string& a, const std::string& b) {
      const auto ma = splitCombination(a), mb = splitCombination(b);
      if (ma.size() != mb.size()) return ma.size() < mb.size();
      for (size_t i = 0; i < ma.size(); ++i) {
        const auto pa = std::find(methods.begin(), methods.end(), ma[i]);
        const auto pb = std::find(methods.begin(), methods.end(), mb[i]);
        if (pa != pb) return pa < pb;
      }
      return false;
    });
    return combos;
  }
  if (spec == "none" || spec.empty()) return combos;
  std::stringstream stream(spec);
  std::string item;
  while (std::getline(stream, item, ',')) {
    std::vector<int> indices;
    for (const std::string& member : splitCombination(item)) {
      const auto it = std::find(methods.begin(), methods.end(), member);
      if (it == methods.end())
        throw Error("--combos: '" + member + "' in '" + item + "' is not one of --methods");
      indices.push_back(int(it - methods.begin()));
    }
    std::sort(indices.begin(), indices.end());
    if (std::adjacent_find(indices.begin(), indices.end()) != indices.end())
      throw Error("--combos: '" + item + "' lists a method twice");
    if (indices.size() < 2) throw Error("--combos: '" + item + "' needs at least two methods");
    const std::string name = join(indices);
    if (std::find(combos.begin(), combos.end(), name) == combos.end()) combos.push_back(name);
  }
  return combos;
}

std::vector<int> parseIntList(const std::string& text, const std::string& flag) {
  std::vector<int> values;
  std::stringstream stream(text);
  std::string item;
  while (std::getline(stream, item, ',')) {
    int v = 0;
    const auto [end, ec] = std::from_chars(item.data(), item.data() + item.size(), v);
    if (ec != std::errc() || end != item.data() + item.size() || v <= 0)
      throw Error(flag + " '" + text + "': '" + item + "' is not a positive integer");
    values.push_back(v);
  }
  if (values.empty()) throw Error(flag + " is empty");
  return values;
}

double estimateRemainingSeconds(const std::vector<FinishedCase>& finished,
                                const std::vector<int>& remainingSpps) {
  if (finished.empty() || remainingSpps.empty()) return 0;
  double n = 0, sx = 0, sy = 0, sxx = 0, sxy = 0;
  for (const FinishedCase& f : finished) {
    const double x = f.spp, y = f.seconds;
    n += 1, sx += x, sy += y, sxx += x * x, sxy += x * y;
  }
  const double variance = n * sxx - sx * sx;
  double a = sy / n, b = 0;  // the mean, until two distinct spp are known
  if (variance > 1e-9 * n * sxx) {
    b = std::max(0.0, (n * sxy - sx * sy) / variance);
    a = std::max(0.0, (sy - b * sx) / n);
  }
  double total = 0;
  for (int spp : remainingSpps) total += a + b * spp;
  return total;
}

}  // namespace chorus::sweep
