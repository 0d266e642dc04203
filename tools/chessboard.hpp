// Chessboard helpers shared by `stereohash calibrate` and `stereohash calibrate-table` (OpenCV,
// host only): finding the inner corners to sub-pixel accuracy and reading the board options.
#pragma once

#include <opencv2/core.hpp>
#include <vector>

namespace sh::tools {

// What a user can ask for: boards of 2..kMaxBoardSide inner corners each way, squares of
// kMinSquareMm..kMaxSquareMm.
inline constexpr int kMaxBoardSide = 64;
inline constexpr double kMinSquareMm = 0.001;
inline constexpr double kMaxSquareMm = 1000.0;

// Inner corners of a cols x rows board in a grey image, refined to sub-pixel; false if absent.
// A view without a board is given up on in tens of milliseconds (OpenCV's fast check).
bool FindBoard(const cv::Mat& gray, cv::Size board, std::vector<cv::Point2f>* corners);

// "9x6" -> 9 x 6 inner corners (2..kMaxBoardSide each); false on anything else.
bool ParseBoardSize(const char* text, cv::Size* board);

// A finite size in millimetres, kMinSquareMm..kMaxSquareMm; false on anything else.
bool ParseSquareMm(const char* text, double* square_mm);

}  // namespace sh::tools
