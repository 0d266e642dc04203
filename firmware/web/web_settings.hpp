// The settings of the commissioning page: every configuration key of the key table with its type,
// range, documentation and value; changes given as `key = value` lines, parsed and validated as
// the configuration file is (the same errors), applied at run time where the firmware allows it,
// and written back into the configuration file on request, atomically (a new file renamed over
// the old one), its comments and other lines kept.
#pragma once

#include <string>

#include "firmware/config_keys.hpp"
#include "firmware/fw_config.hpp"
#include "firmware/web/web_target.hpp"
#include "recog/base/status.hpp"

namespace sh::fw::web {

// Keys the page does not change: which program the file is for, and the page's own security
// (changed in the file only, by someone who can already write it).
bool KeyLockedFromPage(ConfigKeyId key);
// Keys whose value the page never shows (passwords).
bool KeyIsSecret(ConfigKeyId key);

class WebSettings {
 public:
  // `running`: the configuration the firmware started with; `path`: its file, or "" (started
  // without one: nothing to write back).
  WebSettings(const FwConfig& running, const char* path);

  // {"file": ..., "keys": [{"name", "type", "help", "value", "runtime", "locked", "edited"}]}.
  std::string Json() const;

  // Parses `text` (`key = value` lines) onto the settings, validates the whole, applies the keys
  // that apply at run time through `target`. On success *report says per key "applied" or "at
  // the next start"; on error nothing changed.
  Status Change(const char* text, size_t bytes, WebTarget* target, std::string* report);

  // Writes the edited keys into the configuration file: their lines replaced, missing ones
  // appended; the file is replaced by rename.
  Status Save();

  const FwConfig& current() const { return current_; }

 private:
  FwConfig current_;
  ConfigKeySet edited_;  // changed on the page since the start
  std::string path_;
};

// The text of a configuration file with the values of the `edited` keys of `config` in place of
// theirs (lines `key = value`, a comment after the value kept), keys without a line appended.
std::string RewriteConfigText(const std::string& original, const FwConfig& config,
                              const ConfigKeySet& edited);

// Writes `text` to `path` atomically: `path`.new written and synced, renamed over `path`.
Status ReplaceFileAtomically(const char* path, const std::string& text);

}  // namespace sh::fw::web
