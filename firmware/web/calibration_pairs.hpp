// The chessboard pairs the page captures for `stereohash calibrate` (calibrate-table,
// calibrate-handeye) on the host: record_dir/calibration/<8 digits>/left.png and right.png at the
// cameras' full size, and capture.json last. Written by the server thread under a temporary name
// and renamed, so a listed pair is always whole.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "firmware/web/pair_capture.hpp"
#include "recog/base/status.hpp"

namespace sh::fw::web {

// As many pairs as `stereohash calibrate` takes.
inline constexpr size_t kMaxCalibrationPairs = 200;

// record_dir/calibration.
std::string CalibrationDir(const char* record_dir);

// The captured pairs, oldest first.
std::vector<std::string> ListCalibrationPairs(const char* record_dir);

// A pair written: its name and how many pairs the folder holds with it.
struct SavedPair {
  std::string name;
  size_t pairs = 0;
};

// Writes the ready pair of `capture` as the next pair. kResourceExhausted when
// kMaxCalibrationPairs exist, errors naming the path when a file cannot be written.
Result<SavedPair> SaveCalibrationPair(const char* record_dir, const PairCapture& capture);

}  // namespace sh::fw::web
