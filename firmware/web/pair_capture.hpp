// One full-size stereo pair taken from the stream of results for the page's calibration helper:
// the server thread sizes the buffers and arms it, the worker copies the next result's frames
// into them (no heap, no wait: a flag and two copies), and the server thread reads them once
// ready. Used for chessboard pairs, which `stereohash calibrate` needs at the sensor's size.
#pragma once

#include <atomic>
#include <cstdint>
#include <memory>

#include "hal/camera.hpp"
#include "recog/base/status.hpp"

namespace sh::fw::web {

class PairCapture {
 public:
  // Server thread: buffers for frames of up to width x height (each side); allocates once, or
  // again for a larger size. Not while armed (Disarm first).
  Status Prepare(int width, int height);
  // Server thread: the next pair the worker hands over is kept (the one before is dropped).
  void Arm();
  // Server thread: no longer wanted (a capture that timed out); when the worker is copying a
  // pair at that moment, returns once it is done, so that the buffers are the server's again.
  void Disarm();
  // Worker: copies `frame` when armed and both sides are present and fit; never waits.
  void OnFrame(const hal::StereoFrame& frame);
  // Server thread: a pair was copied since Arm().
  bool ready() const { return ready_.load(std::memory_order_acquire); }
  // Server thread, once ready: side 0 left, 1 right.
  const uint8_t* pixels(int side) const { return pixels_[side].get(); }
  int width(int side) const { return width_[side]; }
  int height(int side) const { return height_[side]; }

 private:
  std::unique_ptr<uint8_t[]> pixels_[2];
  std::atomic<size_t> capacity_{0};  // bytes per side (read by the worker before it claims)
  int width_[2] = {0, 0}, height_[2] = {0, 0};
  std::atomic<bool> armed_{false}, ready_{false};
};

}  // namespace sh::fw::web
