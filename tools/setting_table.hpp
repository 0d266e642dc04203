// `--set NAME=VALUE` of the bench commands: each configuration's settings declared once, as a
// table of {name, kind, setter}, which drives the parsing, its errors and the help's list.
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdlib>
#include <cstring>
#include <string>

#include "recog/base/status.hpp"
#include "tools/command.hpp"

namespace sh::tools {

// What a setting's value may be: any finite number, a whole number >= 0 (exact as a float, so at
// most 2^24), or 0 / 1.
enum class SettingKind { kReal, kCount, kFlag };

template <typename Config>
struct Setting {
  const char* name;
  SettingKind kind;
  void (*apply)(float value, Config& config);
};

// The value of `text` for a setting of this kind; an error naming the setting and the value.
inline Status ParseSettingValue(const char* name, SettingKind kind, const char* text,
                                float* value) {
  double v = 0.0;
  const bool number = ParseNumber(text, -HUGE_VAL, HUGE_VAL, &v);
  const bool whole = number && v >= 0.0 && v <= 16777216.0 && v == std::floor(v);
  const bool valid = kind == SettingKind::kReal    ? number
                     : kind == SettingKind::kCount ? whole
                                                   : whole && v <= 1.0;
  if (!valid) {
    return Status::Error(StatusCode::kInvalidArgument, "setting %s: value '%s' is not %s", name,
                         text,
                         kind == SettingKind::kReal    ? "a finite number"
                         : kind == SettingKind::kCount ? "a whole number in 0..16777216"
                                                       : "0 or 1");
  }
  *value = static_cast<float>(v);
  return Status::Ok();
}

// Applies NAME=VALUE from `table` to *config. An unknown name, or a value that is not of the
// setting's kind, is an error naming it, and *config is left as it was.
template <typename Config, size_t N>
Status ApplySetting(const char* setting, const Setting<Config> (&table)[N], Config* config) {
  const char* eq = std::strchr(setting, '=');
  if (eq == nullptr) {
    return Status::Error(StatusCode::kInvalidArgument, "setting %s: expected NAME=VALUE", setting);
  }
  const std::string name(setting, eq);
  for (const Setting<Config>& s : table) {
    if (name != s.name) continue;
    float value = 0.0f;
    SH_RETURN_IF_ERROR(ParseSettingValue(s.name, s.kind, eq + 1, &value));
    s.apply(value, *config);
    return Status::Ok();
  }
  return Status::Error(StatusCode::kInvalidArgument,
                       "unknown setting %s (`stereohash bench recorded --help` lists them)",
                       name.c_str());
}

// The names of `table` for a help text: lines of at most `width` characters, each starting with
// `indent`, separated by newlines.
template <typename Config, size_t N>
std::string SettingNames(const Setting<Config> (&table)[N], const char* indent, size_t width) {
  std::string names;
  size_t line_start = 0;
  for (const Setting<Config>& s : table) {
    if (names.empty() || names.size() - line_start + 1 + std::strlen(s.name) > width) {
      if (!names.empty()) names += '\n';
      line_start = names.size();
      names += indent;
    } else {
      names += ' ';
    }
    names += s.name;
  }
  return names;
}

}  // namespace sh::tools
