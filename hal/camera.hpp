// Stereo capture interface shared by the board backend (hal/linux/libcamera_camera) and the host
// simulator backends (hal/sim/sim_camera, hal/sim/directory_camera).
//
// Memory: every backend allocates its frame buffers in Start(); Capture() hands out views into
// those buffers and never allocates. A captured frame stays valid until the next Capture(), an
// explicit Release() or Stop(), whichever comes first; after that the backend reuses the buffers.
//
// Threading: Start(), Stop(), Capture() and Release() are called from one consumer thread.
// stats() may be called from any thread.
#pragma once

#include <cstdint>

#include "recog/base/status.hpp"
#include "recog/image/frame.hpp"
#include "recog/image/image.hpp"

namespace sh::hal {

enum class StereoSide : uint8_t { kLeft = 0, kRight = 1 };
const char* StereoSideName(StereoSide side);

// What Capture() delivers. In a one-side mode the other camera is not used at all (the board
// backend does not even open it), so the firmware keeps working from one camera when the other
// has failed.
enum class CaptureMode : uint8_t {
  kStereo = 0,     // synchronised pairs
  kLeftOnly = 1,   // left frames alone; StereoFrame::right is empty
  kRightOnly = 2,  // right frames alone; StereoFrame::left is empty
};
const char* CaptureModeName(CaptureMode mode);

// One synchronised left/right pair (or, in a one-side capture mode, one camera's frame).
//
// `left`/`right` are always 8-bit grey: the frame itself for grey sensors, the Y plane read in
// place for Y'CbCr formats (zero-copy), and for RGB888 a luma image the backend converts into a
// buffer of its own. `left_frame`/`right_frame` are the frames in the format delivered (grey,
// RGB888, NV12 or I420, recog/image/frame.hpp), for the paths that read colour; for a grey frame
// they view the same plane as `left`/`right`. Empty on the side a one-side mode does not use.
struct StereoFrame {
  ConstGrayView left;
  ConstGrayView right;
  FrameView left_frame;
  FrameView right_frame;
  // Sensor timestamps (start of exposure as reported by the driver, CLOCK_BOOTTIME/MONOTONIC on
  // the board, synthetic in simulation), nanoseconds.
  int64_t left_timestamp_ns = 0;
  int64_t right_timestamp_ns = 0;
  // Per-camera frame sequence numbers as counted by the driver; gaps reveal sensor-side drops.
  uint32_t left_sequence = 0;
  uint32_t right_sequence = 0;
  // Number of pairs delivered before this one since Start(); gaps reveal pairs dropped because the
  // consumer was slower than the cameras.
  uint64_t pair_index = 0;
};

// Counters since the last Start(). All are cumulative; none is reset by Capture().
struct CameraStats {
  uint64_t frames_paired = 0;         // pairs formed (delivered or dropped for overflow)
  uint64_t pairs_delivered = 0;       // pairs returned by Capture()
  uint64_t left_unpaired_drops = 0;   // left frames with no right partner within tolerance
  uint64_t right_unpaired_drops = 0;  // right frames with no left partner within tolerance
  uint64_t left_overflow_drops = 0;   // left frames dropped because the left queue was full
  uint64_t right_overflow_drops = 0;  // right frames dropped because the right queue was full
  uint64_t pair_overflow_drops = 0;   // pairs dropped because the consumer fell behind
  uint64_t timeouts = 0;              // Capture() calls that ran out of time
  uint64_t no_buffer_drops = 0;       // frames not captured: every buffer of a side was in use
  uint64_t errors = 0;  // failed or corrupt frames, out-of-order timestamps, backend faults
};

class StereoCamera {
 public:
  virtual ~StereoCamera() = default;

  // Allocates and maps all buffers, starts streaming. Fails with a clear Status (e.g. kNotFound
  // when fewer than two cameras exist). Calling Start() twice is kFailedPrecondition.
  virtual Status Start() = 0;
  // Stops streaming and returns all buffers; views handed out earlier become invalid. Safe to
  // call when not started.
  virtual Status Stop() = 0;
  // Waits up to timeout_ms for the next synchronised pair. Releases the previously captured pair
  // first. Errors: kDeadlineExceeded (no pair in time; the message says which side is silent),
  // kUnavailable (camera stopped or disconnected), kFailedPrecondition (not started), and backend
  // specific per-frame errors (e.g. kDataLoss for a corrupt recorded frame; the next call
  // continues with the next frame).
  virtual Status Capture(StereoFrame* out, int timeout_ms) = 0;
  // Gives the buffers of the last captured pair back to the backend before the next Capture(),
  // so the cameras have more buffers to fill while the consumer works on a copy.
  virtual void Release() = 0;
  virtual CameraStats stats() const = 0;

  // Chooses stereo or one-side capture for the next Start() (a started camera keeps its mode
  // until it is stopped). Backends that cannot capture one side alone refuse the one-side modes
  // with kUnimplemented.
  virtual Status SetCaptureMode(CaptureMode mode) {
    if (mode == CaptureMode::kStereo) return Status::Ok();
    return Status::Error(StatusCode::kUnimplemented, "this camera captures stereo pairs only");
  }
  virtual CaptureMode capture_mode() const { return CaptureMode::kStereo; }
  // Asks for colour frames from the next Start() (the model set holds colour parts) or grey ones
  // (false, the default). A backend that can give colour delivers a Y'CbCr format (the grey path
  // keeps reading the Y plane in place) or RGB888; one that cannot, or a sensor without colour,
  // keeps delivering grey: `left_frame.format` says what arrived. Never fails for that reason.
  virtual void SetColourWanted(bool colour) { (void)colour; }
  // After a stereo Capture() failed: the side that delivered no frame since the last pair while
  // the other one did (the failed camera). kNotFound when both or neither delivered frames.
  virtual Result<StereoSide> SilentSide() const {
    return Status::Error(StatusCode::kNotFound, "this camera does not report a silent side");
  }
};

}  // namespace sh::hal
