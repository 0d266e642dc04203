// The settings a recording carries in DIR/settings.conf (recorder.hpp): every configuration key
// that shapes a result beyond the images themselves, so that a replay (camera = directory in the
// simulator) recognises each pair as the recording did. They are the model set (tables,
// features), the detector preset, the working volume, the table estimate and the one-camera
// fallback, and the model data's identity. The table the volume was bounded by
// travels beside them: table.yaml when the configuration gave it, rig_table.yaml when it was the
// board's own (the simulator's rendered table).
#pragma once

#include <string>

#include "firmware/fw_config.hpp"

namespace sh::fw {

// What the model data loaded at boot was (FileDataSource: the tables' CRC-32, the separate
// features file's; 0 = not loaded, or features from the tables' own set).
struct ModelSetIdentity {
  uint32_t tables_crc32 = 0;
  uint32_t features_crc32 = 0;
};

// settings.conf's text: a comment, then `key = value` lines in the configuration's own syntax.
// The volume keys only when a volume is set (given, or the simulator's box over its table); the
// model data's identity as tables_crc32 and features_crc32 pins, so that a replay of the recorded
// model set refuses a file rebuilt since.
std::string RecordedSettings(const FwConfig& config, const ModelSetIdentity& identity);

// The recorded keys that `recorded` (settings.conf read over the defaults) gives and `config`
// does not, copied into *config as if its file gave them: a replay's own file wins. A pin comes
// with its file only: a replay that names its own tables (or features) replays with those.
void TakeRecordedSettings(const FwConfig& recorded, FwConfig* config);

}  // namespace sh::fw
