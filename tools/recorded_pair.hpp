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
};

// kNotFound when the folder holds neither image.
Status FindRecordedPair(const char* scene_dir, RecordedPair* out);

}  // namespace sh::tools
