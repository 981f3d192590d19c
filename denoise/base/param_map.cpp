#include "denoise/base/param_map.h"

#include <charconv>
#include <cmath>
#include <sstream>

#include "common/error.h"

namespace chorus {

ParamMap ParamMap::parse(const std::string& text, const std::string& context) {
  ParamMap params;
  std::stringstream stream(text);
  std::string item;
  while (std::getline(stream, item, ':')) {
    if (item.empty()) continue;
    const size_t eq = item.find('=');
    if (eq == std::string::npos || eq == 0 || eq + 1 == item.size())
      throw Error(context + ": parameter '" + item + "' is not of the form key=value");
    const std::string key = item.substr(0, eq);
    // Given twice, one value would silently win (`alpha=nan:alpha=4` passed the finite check).
    if (params.has(key)) throw Error(context + ": parameter " + key + " is given twice");
    params.set(key, item.substr(eq + 1));
  }
  return params;
}

const std::string* ParamMap::find(const std::string& key) {
  auto it = values_.find(key);
  if (it == values_.end()) return nullptr;
  read_.insert(key);
  return &it->second;
}

float ParamMap::getFloat(const std::string& key, float defaultValue) {
  const std::string* v = find(key);
  if (!v) return defaultValue;
  try {
    size_t used = 0;
    const float value = std::stof(*v, &used);
    if (used == v->size() && std::isfinite(value)) return value;
  } catch (const std::exception&) {
  }
  throw Error("parameter " + key + "=" + *v + " is not a finite number");
}

int ParamMap::getInt(const std::string& key, int defaultValue) {
  const std::string* v = find(key);
  if (!v) return defaultValue;
  int value = 0;
  auto [end, ec] = std::from_chars(v->data(), v->data() + v->size(), value);
  if (ec != std::errc() || end != v->data() + v->size())
    throw Error("parameter " + key + "=" + *v + " is not an integer");
  return value;
}

bool ParamMap::getBool(const std::string& key, bool defaultValue) {
  const std::string* v = find(key);
  if (!v) return defaultValue;
  if (*v == "1" || *v == "true" || *v == "on") return true;
  if (*v == "0" || *v == "false" || *v == "off") return false;
  throw Error("parameter " + key + "=" + *v + " is not a boolean (true/false)");
}

std::string ParamMap::getString(const std::string& key, const std::string& defaultValue) {
  const std::string* v = find(key);
  return v ? *v : defaultValue;
}

void ParamMap::rejectUnread(const std::string& context) const {
  for (const auto& [key, value] : values_)
    if (!read_.count(key)) throw Error(context + ": unknown parameter '" + key + "'");
}

}  // namespace chorus
