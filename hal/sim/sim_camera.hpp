// Host simulator stereo camera: frames come from a FrameSource, timestamps from a synthetic clock,
// pairing from the same StereoPairer the board backend uses, and faults can be injected.
//
// Pull model: Capture() produces frames on demand (up to kSimFramesPerCapture per call) instead of
// running a free-running thread, so that tests are deterministic. When no pair can be formed from
// those frames, Capture() waits timeout_ms like the real backend and reports which side is silent.
#pragma once

#include <cstdint>
#include <memory>

#include "hal/camera.hpp"
#include "hal/sim/sim_camera_source.hpp"
#include "hal/stereo_pairing.hpp"

namespace sh::hal {

// Buffers per side: a full side queue and the frame being rendered. A frame is rendered only
// inside Capture(), after it has released the consumer's pair and found the pair queue empty
// (TryTakePair), so at that moment the side queue (at most kStereoQueueDepth frames) holds every
// other buffer of the side; the queued pairs and the held pair never coexist with a rendering.
// Should a side's pool be empty all the same, the frame is not captured on either side and is
// counted (CameraStats::no_buffer_drops), as a camera without a free buffer drops a frame. The
// board's libcamera backend keeps its own count (kLibcameraBufferCount).
inline constexpr size_t kSimBuffersPerSide = kStereoQueueDepth + 1;
// Frames produced by one Capture() before it gives up and waits; bounds the work per call when a
// fault keeps one side from pairing.
inline constexpr int kSimFramesPerCapture = 8;

struct SimCameraConfig {
  int64_t frame_period_ns = 33'333'333;  // 30 fps
  int64_t first_timestamp_ns = 1'000'000'000;
  PairingConfig pairing;

  // Fault injection. The left camera is the reference clock.
  int64_t right_offset_ns = 0;   // constant skew of right timestamps
  int64_t right_drift_ppb = 0;   // right clock runs fast (positive) by parts per billion
  int64_t jitter_ns = 0;         // each timestamp moves by a pseudo-random amount in +-jitter_ns
  uint32_t jitter_seed = 1;      // same seed, same jitter sequence
  int64_t left_stop_after = -1;  // deliver only this many left frames (-1: never stop)
  int64_t right_stop_after = -1;
  uint32_t drop_left_every = 0;  // drop every n-th left frame, counting from frame n-1 (0: never)
  uint32_t drop_right_every = 0;
  // A camera that is not connected: Start() fails (not found) in every mode that needs it.
  bool left_absent = false;
  bool right_absent = false;
  // The stop, drop and absence faults apply in the first `fault_starts` Start()s only (-1: in
  // all), so a test can have a camera come back when the firmware restarts it.
  int64_t fault_starts = -1;
};

class SimCamera final : public StereoCamera {
 public:
  // `source` must outlive the camera.
  SimCamera(FrameSource* source, const SimCameraConfig& config);
  ~SimCamera() override;

  Status Start() override;
  Status Stop() override;
  Status Capture(StereoFrame* out, int timeout_ms) override;
  void Release() override;
  CameraStats stats() const override;
  Status SetCaptureMode(CaptureMode mode) override;
  CaptureMode capture_mode() const override { return mode_; }
  Result<StereoSide> SilentSide() const override { return pairer_.SilentSide(); }

  int width() const { return width_; }
  int height() const { return height_; }
  // The delivered frames' format (the source's: grey, or NV12 for a world with colour parts).
  FrameFormat format() const { return format_; }

 private:
  struct SidePool {
    uint8_t* buffers[kSimBuffersPerSide] = {};
    uint32_t free_ids[kSimBuffersPerSide] = {};
    size_t free_count = 0;
  };

  // Produces frame next_frame_ and pushes what the fault settings let through.
  Status ProduceFrame();
  int64_t Timestamp(StereoSide side, uint64_t frame_index);
  void GiveBack(const Vector<RecycledFrame>& recycled);
  void GiveBack(StereoSide side, uint32_t buffer_id);
  bool SideStopped(StereoSide side) const;
  bool FaultsActive() const;
  GrayView BufferView(StereoSide side, uint32_t buffer_id) const;
  // The NV12 chroma plane behind the Y plane of a buffer (kNv12 only).
  ImageView<CbCr8> ChromaView(StereoSide side, uint32_t buffer_id) const;
  FrameView FrameOf(StereoSide side, uint32_t buffer_id) const;

  FrameSource* source_;
  SimCameraConfig config_;
  StereoPairer pairer_;
  std::unique_ptr<uint8_t[]> memory_;
  SidePool pools_[2];
  int width_ = 0;
  int height_ = 0;
  FrameFormat format_ = FrameFormat::kGray8;
  size_t frame_bytes_ = 0;  // one buffer: the grey image, or Y then the chroma pairs
  bool started_ = false;
  CaptureMode mode_ = CaptureMode::kStereo;
  int64_t starts_ = 0;    // Start() calls that succeeded
  Status end_of_stream_;  // non-ok once the source reported kOutOfRange
  uint64_t next_frame_ = 0;
  uint64_t delivered_[2] = {};
  uint32_t jitter_state_ = 1;
  bool holding_ = false;
  FramePair held_;
  uint64_t no_buffer_drops_ = 0;
};

}  // namespace sh::hal
