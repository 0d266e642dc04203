#include "firmware/recorded_settings.hpp"

#include "firmware/config_keys.hpp"

namespace sh::fw {
namespace {

// Every key here changes which models, edges, features or hypotheses a frame yields. Not here:
// the threads (one or several give the same result) and the budget (a replay on a desk is not
// timed as the board was).
constexpr ConfigKeyId kRecordedKeys[] = {ConfigKeyId::tables,
                                         ConfigKeyId::features,
                                         ConfigKeyId::background,
                                         ConfigKeyId::volume_frame,
                                         ConfigKeyId::volume_min_mm,
                                         ConfigKeyId::volume_max_mm,
                                         ConfigKeyId::table_estimate,
                                         ConfigKeyId::table_confirm_frames,
                                         ConfigKeyId::table_check_frames,
                                         ConfigKeyId::mono_fallback};

bool IsVolumeKey(ConfigKeyId id) {
  return id == ConfigKeyId::volume_frame || id == ConfigKeyId::volume_min_mm ||
         id == ConfigKeyId::volume_max_mm;
}

}  // namespace

std::string RecordedSettings(const FwConfig& config) {
  std::string text = "# the recognition settings of this recording\n";
  for (const ConfigKeyId id : kRecordedKeys) {
    if (IsVolumeKey(id) && !config.volume_set()) continue;
    if (id == ConfigKeyId::features && config.features[0] == '\0') continue;  // the tables' own
    const ConfigKey& key = ConfigKeys()[static_cast<size_t>(id)];
    char value[kConfigPathMax];
    FormatConfigValue(key, config, value, sizeof(value));
    text.append(key.name).append(" = ").append(value).append("\n");
  }
  return text;
}

void TakeRecordedSettings(const FwConfig& recorded, FwConfig* config) {
  for (const ConfigKeyId id : kRecordedKeys) {
    if (recorded.Given(id) && !config->Given(id)) {
      CopyConfigKey(ConfigKeys()[static_cast<size_t>(id)], recorded, config);
    }
  }
}

}  // namespace sh::fw
