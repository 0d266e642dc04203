// Chessboard helpers shared by `stereohash calibrate` and `stereohash calibrate-table` (OpenCV,
// host only): finding the inner corners to sub-pixel accuracy and reading the board options.
#pragma once

#include <opencv2/core.hpp>
#include <vector>

namespace sh::tools {

// Inner corners of a cols x rows board in a grey image, refined to sub-pixel; false if absent.
bool FindBoard(const cv::Mat& gray, cv::Size board, std::vector<cv::Point2f>* corners);

// "9x6" -> 9 x 6 inner corners (at least 2 x 2); false on anything else.
bool ParseBoardSize(const char* text, cv::Size* board);

// A positive finite size in millimetres; false on anything else.
bool ParseSquareMm(const char* text, double* square_mm);

}  // namespace sh::tools
