#include "tools/chessboard.hpp"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include "tools/command.hpp"

namespace sh::tools {

bool FindBoard(const cv::Mat& gray, cv::Size board, std::vector<cv::Point2f>* corners) {
  // The fast check gives up on views without a board in tens of milliseconds instead of the
  // seconds the full search spends on noise.
  if (!cv::findChessboardCorners(
          gray, board, *corners,
          cv::CALIB_CB_ADAPTIVE_THRESH | cv::CALIB_CB_NORMALIZE_IMAGE | cv::CALIB_CB_FAST_CHECK)) {
    return false;
  }
  cv::cornerSubPix(gray, *corners, cv::Size(11, 11), cv::Size(-1, -1),
                   cv::TermCriteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 30, 0.01));
  return true;
}

bool ParseBoardSize(const char* text, cv::Size* board) {
  int cols = 0, rows = 0;
  char tail = '\0';
  if (std::strlen(text) > 16 || std::sscanf(text, "%dx%d%c", &cols, &rows, &tail) != 2 ||
      cols < 2 || rows < 2 || cols > kMaxBoardSide || rows > kMaxBoardSide) {
    return false;
  }
  *board = cv::Size(cols, rows);
  return true;
}

bool ParseSquareMm(const char* text, double* square_mm) {
  return ParseNumber(text, kMinSquareMm, kMaxSquareMm, square_mm);
}

}  // namespace sh::tools
