#include "tools/board_detection.hpp"

#include <poll.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <new>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "tools/chessboard.hpp"

namespace sh::tools {
namespace {

// The record the child writes to the pipe: a header, the corners, the message text.
struct RecordHeader {
  int32_t outcome;
  int32_t width, height;
  int32_t n_left, n_right;
  int32_t message_length;
};

// AddressSanitizer and ThreadSanitizer map their shadow memory private and writable, which
// RLIMIT_DATA counts: in their builds (the sanitizer test runs) a heap limit is exceeded before
// the child allocates anything, so it searches without one.
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
constexpr bool kHeapLimitUsable = false;
#elif defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(thread_sanitizer)
constexpr bool kHeapLimitUsable = false;
#else
constexpr bool kHeapLimitUsable = true;
#endif
#else
constexpr bool kHeapLimitUsable = true;
#endif

double NowS() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
}

bool WriteAll(int fd, const void* data, size_t n) {
  const auto* p = static_cast<const char*>(data);
  while (n > 0) {
    const ssize_t w = write(fd, p, n);
    if (w < 0 && errno == EINTR) continue;
    if (w <= 0) return false;
    p += w;
    n -= size_t(w);
  }
  return true;
}

PairDetection Detect(const std::string& left_path, const std::string& right_path, cv::Size board,
                     const DetectionLimits& limits) {
  PairDetection d;
  const std::string* paths[2] = {&left_path, &right_path};
  std::vector<cv::Point2f>* corners[2] = {&d.left, &d.right};
  for (int side = 0; side < 2; ++side) {
    const cv::Mat image = cv::imread(*paths[side], cv::IMREAD_GRAYSCALE);
    if (image.empty()) {
      d.message = "cannot read '" + *paths[side] + "' as an image";
      return d;
    }
    char size_text[160];
    if (image.cols > limits.max_width || image.rows > limits.max_height) {
      std::snprintf(size_text, sizeof(size_text),
                    "is %dx%d, larger than the %dx%d the recogniser supports", image.cols,
                    image.rows, limits.max_width, limits.max_height);
      d.message = "'" + *paths[side] + "' ";
      d.message += size_text;
      return d;
    }
    if (side == 0) {
      d.image_size = image.size();
    } else if (image.size() != d.image_size) {
      std::snprintf(size_text, sizeof(size_text), "is %dx%d, the left image %dx%d", image.cols,
                    image.rows, d.image_size.width, d.image_size.height);
      d.message = "'" + right_path + "' ";
      d.message += size_text;
      return d;
    }
    if (!FindBoard(image, board, corners[side])) {
      d.outcome = PairDetection::Outcome::kNotFound;
      d.message = "no board in '" + *paths[side] + "'";
      return d;
    }
  }
  d.outcome = PairDetection::Outcome::kFound;
  return d;
}

[[noreturn]] void ChildMain(int fd, const std::string& left_path, const std::string& right_path,
                            cv::Size board, const DetectionLimits& limits) {
  if (kHeapLimitUsable) {
    const rlimit heap{limits.memory_limit_bytes, limits.memory_limit_bytes};
    setrlimit(RLIMIT_DATA, &heap);
  }
  PairDetection d;
  try {
    d = Detect(left_path, right_path, board, limits);
  } catch (const cv::Exception& e) {
    d.message = std::string("OpenCV failed: ") + e.what();
  } catch (const std::bad_alloc&) {
    d.message = "out of memory decoding the images (limit " +
                std::to_string(limits.memory_limit_bytes >> 20) + " MiB)";
  }
  const RecordHeader h{int32_t(d.outcome),     d.image_size.width,      d.image_size.height,
                       int32_t(d.left.size()), int32_t(d.right.size()), int32_t(d.message.size())};
  const bool ok = WriteAll(fd, &h, sizeof(h)) &&
                  WriteAll(fd, d.left.data(), d.left.size() * sizeof(cv::Point2f)) &&
                  WriteAll(fd, d.right.data(), d.right.size() * sizeof(cv::Point2f)) &&
                  WriteAll(fd, d.message.data(), d.message.size());
  _exit(ok ? 0 : 1);
}

// Reads the child's whole record until end of file or the deadline.
bool ReadRecord(int fd, double deadline_s, std::string* bytes) {
  char buffer[16384];
  for (;;) {
    const double left_s = deadline_s - NowS();
    if (left_s <= 0) return false;
    pollfd p{fd, POLLIN, 0};
    const int ready = poll(&p, 1, int(std::ceil(left_s * 1000.0)));
    if (ready < 0 && errno == EINTR) continue;
    if (ready <= 0) return false;
    const ssize_t n = read(fd, buffer, sizeof(buffer));
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return true;  // end of file (or an error, which the record check reports)
    bytes->append(buffer, size_t(n));
  }
}

PairDetection ParseRecord(const std::string& bytes) {
  PairDetection d;
  RecordHeader h{};
  if (bytes.size() < sizeof(h)) {
    d.message = "the board search ended without a result";
    return d;
  }
  std::memcpy(&h, bytes.data(), sizeof(h));
  const size_t corners = size_t(h.n_left) + size_t(h.n_right);
  if (h.n_left < 0 || h.n_right < 0 || h.message_length < 0 ||
      bytes.size() != sizeof(h) + corners * sizeof(cv::Point2f) + size_t(h.message_length)) {
    d.message = "the board search returned a damaged result";
    return d;
  }
  d.outcome = static_cast<PairDetection::Outcome>(h.outcome);
  d.image_size = cv::Size(h.width, h.height);
  d.left.resize(size_t(h.n_left));
  d.right.resize(size_t(h.n_right));
  const char* p = bytes.data() + sizeof(h);
  // An empty vector's data() may be null, which memcpy must not get even for zero bytes.
  if (!d.left.empty()) std::memcpy(d.left.data(), p, d.left.size() * sizeof(cv::Point2f));
  p += d.left.size() * sizeof(cv::Point2f);
  if (!d.right.empty()) std::memcpy(d.right.data(), p, d.right.size() * sizeof(cv::Point2f));
  p += d.right.size() * sizeof(cv::Point2f);
  d.message.assign(p, size_t(h.message_length));
  return d;
}

}  // namespace

PairDetection DetectBoardPair(const std::string& left_path, const std::string& right_path,
                              cv::Size board, const DetectionLimits& limits) {
  PairDetection d;
  int fds[2];
  if (pipe(fds) != 0) {
    d.message = std::string("pipe: ") + std::strerror(errno);
    return d;
  }
  std::fflush(nullptr);  // nothing buffered may be written twice
  const pid_t child = fork();
  if (child < 0) {
    d.message = std::string("fork: ") + std::strerror(errno);
    close(fds[0]);
    close(fds[1]);
    return d;
  }
  if (child == 0) {
    close(fds[0]);
    ChildMain(fds[1], left_path, right_path, board, limits);
  }
  close(fds[1]);
  std::string bytes;
  const bool finished = ReadRecord(fds[0], NowS() + limits.time_limit_s, &bytes);
  close(fds[0]);
  if (!finished) kill(child, SIGKILL);
  int status = 0;
  while (waitpid(child, &status, 0) < 0 && errno == EINTR) {
  }
  if (!finished) {
    d.outcome = PairDetection::Outcome::kTimedOut;
    char text[96];
    std::snprintf(text, sizeof(text), "reading and searching the pair took longer than %g s",
                  limits.time_limit_s);
    d.message = text;
    return d;
  }
  if (WIFSIGNALED(status)) {
    d.message = "the board search was stopped by signal " + std::to_string(WTERMSIG(status)) +
                " (the " + std::to_string(limits.memory_limit_bytes >> 20) +
                " MiB memory limit, or a damaged image)";
    return d;
  }
  return ParseRecord(bytes);
}

}  // namespace sh::tools
