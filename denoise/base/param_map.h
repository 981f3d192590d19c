#pragma once
// Parameter overrides for a denoiser, parsed from "name:key=value:key=value". Every key must be
// read by the denoiser it was given to: unread keys (usually typos) are reported as errors by
// rejectUnread(), in the manner of Mitsuba's Properties::unqueried().
#include <map>
#include <set>
#include <string>

namespace chorus {

class ParamMap {
 public:
  ParamMap() = default;
  // Parses "key=value:key=value" (the part after the method name). Throws chorus::Error.
  static ParamMap parse(const std::string& text, const std::string& context);

  void set(const std::string& key, const std::string& value) { values_[key] = value; }
  bool has(const std::string& key) const { return values_.count(key) != 0; }

  float getFloat(const std::string& key, float defaultValue);
  int getInt(const std::string& key, int defaultValue);
  bool getBool(const std::string& key, bool defaultValue);
  std::string getString(const std::string& key, const std::string& defaultValue);

  // Throws chorus::Error("<context>: unknown parameter 'x'") for a key nobody read.
  void rejectUnread(const std::string& context) const;

 private:
  const std::string* find(const std::string& key);

  std::map<std::string, std::string> values_;
  std::set<std::string> read_;
};

}  // namespace chorus
