// A recorded stereo pair on disk: a scene folder of a recorded-scenes set (../shared/scenes
// layout) or of a firmware recording (record_dir), with the set's calib.yaml and table.yaml one
// level up.
#pragma once

#include <cstdint>
#include <string>

#include "recog/base/status.hpp"

namespace sh::tools {

// The working volume a firmware recording was recognised in (settings.conf: volume_frame,
// volume_min_mm, volume_max_mm), so that a replay bounds the scene as the board did.
struct RecordedVolume {
  bool present = false;         // both bounds given
  bool in_table_frame = false;  // volume_frame = table (else the left camera's frame)
  float min_mm[3] = {0, 0, 0};
  float max_mm[3] = {0, 0, 0};
};

struct RecordedPair {
  // DIR/left.png or .pgm, DIR/right.png or .pgm; one of them "" for a folder recorded while on
  // one camera (then recognised from the other image alone).
  std::string left, right;
  std::string calib;  // DIR/../calib.yaml, "" if there is none (then --calib must give it)
  std::string table;  // DIR/../table.yaml, "" if there is none
  // DIR/../rig_table.yaml, "" if there is none: the board's own table, which bounded the volume
  // of a recording made without a table file.
  std::string rig_table;
  RecordedVolume volume;
  // The detector preset of a firmware recording (DIR/../settings.conf, `background = dark` or
  // `light`), "" when the recording was recognised automatically or names no preset.
  std::string background;
  // The model set a firmware recording was recognised with (settings.conf `tables`), "" for the
  // built-in tables or a recording that does not say.
  std::string tables;
  // The CRC-32 of that model set as recorded (settings.conf tables_crc32), 0 if it names none.
  uint32_t tables_crc32 = 0;
};

// kNotFound when the folder holds neither image; kInvalidArgument for a settings.conf whose
// background is none of auto, dark and light, or whose volume keys do not parse (three numbers
// each, min below max, frame camera or table).
Status FindRecordedPair(const char* scene_dir, RecordedPair* out);

// Whether the recording's own model set, `tables_path` (nullptr = the built-in tables), is still
// the one it was recognised with: kFailedPrecondition naming both CRC-32s when the file was
// rebuilt or replaced since. OK when the recording pins none.
Status CheckRecordedTables(const RecordedPair& recorded, const char* tables_path);

}  // namespace sh::tools
