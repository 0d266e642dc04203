#include "firmware/web/pair_capture.hpp"

#include <cstring>
#include <new>
#include <thread>

namespace sh::fw::web {

Status PairCapture::Prepare(int width, int height) {
  if (width <= 0 || height <= 0) {
    return Status::Error(StatusCode::kFailedPrecondition, "no camera image size is known yet");
  }
  const size_t bytes = static_cast<size_t>(width) * static_cast<size_t>(height);
  if (bytes <= capacity_) return Status::Ok();
  for (auto& p : pixels_) {
    p.reset(new (std::nothrow) uint8_t[bytes]);
    if (p == nullptr) {
      capacity_ = 0;
      return Status::Error(StatusCode::kUnavailable, "cannot allocate %zu bytes for a pair",
                           2 * bytes);
    }
  }
  capacity_ = bytes;
  return Status::Ok();
}

void PairCapture::Arm() {
  ready_.store(false, std::memory_order_release);
  armed_.store(capacity_ > 0, std::memory_order_release);
}

void PairCapture::Disarm() {
  // The worker claimed the pair (exchange below) and is copying it: that takes a moment.
  if (!armed_.exchange(false, std::memory_order_acq_rel)) {
    while (!ready_.load(std::memory_order_acquire)) std::this_thread::yield();
  }
}

void PairCapture::OnFrame(const hal::StereoFrame& frame) {
  const ConstGrayView sides[2] = {frame.left, frame.right};
  for (const ConstGrayView& v : sides) {
    // One camera out, or a frame larger than prepared for: wait for a full pair that fits.
    if (v.empty() || static_cast<size_t>(v.width) * static_cast<size_t>(v.height) > capacity_) {
      return;
    }
  }
  // Claimed: from here the server thread waits for ready() instead of touching the buffers.
  if (!armed_.exchange(false, std::memory_order_acq_rel)) return;
  for (int side = 0; side < 2; ++side) {
    const ConstGrayView& v = sides[side];
    for (int y = 0; y < v.height; ++y) {
      std::memcpy(pixels_[side].get() + static_cast<size_t>(y) * v.width, v.row(y),
                  static_cast<size_t>(v.width));
    }
    width_[side] = v.width;
    height_[side] = v.height;
  }
  ready_.store(true, std::memory_order_release);
}

}  // namespace sh::fw::web
