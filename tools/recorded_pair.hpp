// A recorded stereo pair on disk: a scene folder of a recorded-scenes set (../shared/scenes
// layout) or of a firmware recording (record_dir), with the set's calib.yaml and table.yaml one
// level up.
#pragma once

#include <string>

#include "recog/base/status.hpp"

namespace sh::tools {

struct RecordedPair {
  // DIR/left.png or .pgm, DIR/right.png or .pgm; one of them "" for a folder recorded while on
  // one camera (then recognised from the other image alone).
  std::string left, right;
  std::string calib;  // DIR/../calib.yaml, "" if there is none (then --calib must give it)
  std::string table;  // DIR/../table.yaml, "" if there is none
  // The detector preset of a firmware recording (DIR/../settings.conf, `background = dark` or
  // `light`), "" when the recording was recognised automatically or names no preset.
  std::string background;
};

// kNotFound when the folder holds neither image; kInvalidArgument for a settings.conf whose
// background is none of auto, dark and light.
Status FindRecordedPair(const char* scene_dir, RecordedPair* out);

}  // namespace sh::tools
