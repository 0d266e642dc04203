// Chessboard corners of one stereo pair for `stereohash calibrate`, found in a child process: a
// pathological image (noise that keeps the detector searching, a decompression bomb, a path
// that never delivers data) costs at most the time limit and the memory limit, and the
// calibration carries on with the other pairs. Host only (OpenCV).
#pragma once

#include <cstddef>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

namespace sh::tools {

struct DetectionLimits {
  double time_limit_s = 10.0;                     // per pair, reading and searching both images
  size_t memory_limit_bytes = size_t{512} << 20;  // heap of the child (RLIMIT_DATA)
  int max_width = 0, max_height = 0;              // larger images are refused
};

struct PairDetection {
  enum class Outcome { kFound, kNotFound, kTimedOut, kFailed };
  Outcome outcome = Outcome::kFailed;
  cv::Size image_size;  // of the left image (the right one is checked against it)
  std::vector<cv::Point2f> left, right;
  std::string message;  // kFailed: what went wrong; kNotFound: in which image
};

// Reads both images as grey, checks their sizes, finds `board` inner corners in each and refines
// them to sub-pixel accuracy.
PairDetection DetectBoardPair(const std::string& left_path, const std::string& right_path,
                              cv::Size board, const DetectionLimits& limits);

}  // namespace sh::tools
