#include "firmware/recorded_settings.hpp"

#include "firmware/config_keys.hpp"

namespace sh::fw {
namespace {

// Every key here changes which models, edges, features or hypotheses a frame yields. Not here:
// the threads (one or several give the same result) and the budget (a replay on a desk is not
// timed as the board was).
constexpr ConfigKeyId kRecordedKeys[] = {ConfigKeyId::tables,
                                         ConfigKeyId::tables_crc32,
                                         ConfigKeyId::features,
                                         ConfigKeyId::features_crc32,
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

// The file key a pin belongs to, or the key itself.
ConfigKeyId PinnedFile(ConfigKeyId id) {
  if (id == ConfigKeyId::tables_crc32) return ConfigKeyId::tables;
  if (id == ConfigKeyId::features_crc32) return ConfigKeyId::features;
  return id;
}

void AppendKey(ConfigKeyId id, const FwConfig& values, std::string* text) {
  const ConfigKey& key = ConfigKeys()[static_cast<size_t>(id)];
  char value[kConfigPathMax];
  FormatConfigValue(key, values, value, sizeof(value));
  text->append(key.name).append(" = ").append(value).append("\n");
}

}  // namespace

std::string RecordedSettings(const FwConfig& config, const ModelSetIdentity& identity) {
  std::string text = "# the recognition settings of this recording\n";
  FwConfig pins;
  pins.tables_crc32 = identity.tables_crc32;
  pins.features_crc32 = identity.features_crc32;
  const bool own_features = config.features[0] != '\0';  // else the tables' set's, or none
  for (const ConfigKeyId id : kRecordedKeys) {
    if (IsVolumeKey(id) && !config.volume_set()) continue;
    if (id == ConfigKeyId::features && !own_features) continue;
    if (id == ConfigKeyId::tables_crc32 && identity.tables_crc32 == 0) continue;
    if (id == ConfigKeyId::features_crc32 && (!own_features || identity.features_crc32 == 0)) {
      continue;
    }
    AppendKey(id, PinnedFile(id) != id ? pins : config, &text);
  }
  return text;
}

void TakeRecordedSettings(const FwConfig& recorded, FwConfig* config) {
  const ConfigKeySet own = config->given;  // the keys the replay's file gave
  for (const ConfigKeyId id : kRecordedKeys) {
    if (own.Has(static_cast<size_t>(PinnedFile(id))) && PinnedFile(id) != id) continue;
    if (recorded.Given(id) && !own.Has(static_cast<size_t>(id))) {
      CopyConfigKey(ConfigKeys()[static_cast<size_t>(id)], recorded, config);
    }
  }
}

}  // namespace sh::fw
