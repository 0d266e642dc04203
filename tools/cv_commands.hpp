// The commands built with OpenCV (calibrate, calibrate-table, calibrate-handeye and the OpenCV
// peer of `bench textured`) live in a second program, stereohash-cv, so that `stereohash` and its
// recognition commands load none of OpenCV's shared libraries (53 MB resident before an image is
// read: docs/memory.md). `stereohash <command>` runs stereohash-cv (tools/cv_program.hpp), so the
// user's commands are unchanged. What both programs say of those commands:
#pragma once

namespace sh::tools {

// One summary line per command, for `stereohash --help` and `stereohash-cv --help` alike.
inline constexpr char kCalibrateSummary[] = "stereo calibration from chessboard image pairs";
inline constexpr char kCalibrateTableSummary[] =
    "table pose (table.yaml) from a chessboard lying on the table";
inline constexpr char kCalibrateHandEyeSummary[] =
    "camera pose in the robot's frame from robot stations (hand-eye)";

// The program's file name, looked up in the directory of the running `stereohash`.
inline constexpr char kCvProgramName[] = "stereohash-cv";

}  // namespace sh::tools
