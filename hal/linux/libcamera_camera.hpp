// Board stereo camera: two libcamera cameras streaming freely, paired by sensor timestamp. In a
// one-side capture mode (SetCaptureMode, for the next Start()) only that camera is opened, so a
// failed or unplugged other camera does not keep the board from capturing.
//
// Start() opens one CameraManager, picks the two cameras, gives both the same configuration,
// allocates the buffers with FrameBufferAllocator, maps the grey (luma) plane of every buffer once
// and queues one request per buffer. Completed requests go to the StereoPairer from libcamera's
// thread; frames that cannot be paired are requeued at once, paired frames when the consumer
// releases them (next Capture() or Release()). This code allocates nothing after Start();
// libcamera itself may allocate while handling requests.
//
// Pixel format: for grey (the default) the first of R8 (8-bit grey sensors), NV12, YUV420 that
// the camera accepts for the requested role without changing it, of which only the Y plane is
// mapped and used (zero-copy). With SetColourWanted(true) (a model set with colour parts) the
// first of NV12, YUV420 (both asked for as sYCC, BT.601 full range; the colour space the pipeline
// settles on is read back), BGR888 (R, G, B bytes in memory) and R8; Y'CbCr frames keep the Y
// plane as the grey view in place, RGB frames get a grey view converted into a buffer of the
// backend's own when the frame completes. Both cameras must accept exactly the format, size and
// colour space the left one ended up with, otherwise Start() fails.
//
// This header does not include libcamera: the firmware links the library without its headers.
#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include "hal/camera.hpp"
#include "hal/stereo_pairing.hpp"

namespace sh::hal {

// Buffers per camera: everything the pairer can hold (side queue, pair queue, the consumer's
// pair) plus two for the sensor to fill. libcamera may adjust it; at most kMaxLibcameraBuffers.
inline constexpr unsigned kLibcameraBufferCount = kStereoQueueDepth + kStereoPairDepth + 3;
inline constexpr unsigned kMaxLibcameraBuffers = 16;

enum class LibcameraRole : uint8_t {
  kVideoRecording,  // ISP output, continuous streaming: usual choice
  kViewfinder,
  kRaw,  // sensor output without ISP: only 8-bit grey sensors (R8) qualify
};

struct LibcameraStereoConfig {
  // Camera selection: ids as printed by `cam --list` (Camera::id()) take precedence; when empty,
  // indices into CameraManager::cameras() (libcamera sorts them by id's discovery order).
  std::string left_id;
  std::string right_id;
  int left_index = 0;
  int right_index = 1;
  // The sensor's image size, as calibrated. Up to kMaxImageWidth x kMaxImageHeight it is the
  // stream's size; a larger sensor (up to kMaxSensorWidth x kMaxSensorHeight) is asked for its
  // size binned by BinFactorFor(), which a sensor's binned mode or the ISP's scaler delivers. A
  // camera that offers neither is asked for the sensor's size, and each frame is binned here
  // (LibcameraStreamInfo::software_bin); one that offers that neither is refused.
  int width = 1280;
  int height = 800;
  LibcameraRole role = LibcameraRole::kVideoRecording;
  PairingConfig pairing;
};

// What Start() settled on, for logs and calibration checks.
struct LibcameraStreamInfo {
  std::string left_id;
  std::string right_id;
  std::string pixel_format;                  // e.g. "R8", "NV12"
  FrameFormat format = FrameFormat::kGray8;  // as handed out in StereoFrame::left_frame
  YcbcrEncoding encoding = YcbcrEncoding::kRec601;
  YcbcrRange range = YcbcrRange::kFull;
  int width = 0;
  int height = 0;
  int stride = 0;  // bytes per row of the grey plane
  unsigned buffers_per_camera = 0;
  // 1, or the factor this HAL bins each frame by itself: a sensor larger than the pipeline's
  // frames whose camera offered neither a binned mode nor a scaled stream of the binned size.
  // width and height are then the binned size; Y'CbCr frames are then handed out grey.
  int software_bin = 1;
};

class LibcameraStereoCamera final : public StereoCamera {
 public:
  explicit LibcameraStereoCamera(const LibcameraStereoConfig& config);
  ~LibcameraStereoCamera() override;
  LibcameraStereoCamera(const LibcameraStereoCamera&) = delete;
  LibcameraStereoCamera& operator=(const LibcameraStereoCamera&) = delete;

  // kNotFound "libcamera found N cameras, need 2" or an unknown id; kUnavailable when a camera is
  // in use or fails to start; kFailedPrecondition when the two cameras cannot share one
  // configuration; kInternal for allocation or mapping failures.
  Status Start() override;
  Status Stop() override;
  Status Capture(StereoFrame* out, int timeout_ms) override;
  void Release() override;
  CameraStats stats() const override;
  Status SetCaptureMode(CaptureMode mode) override;
  CaptureMode capture_mode() const override;
  Result<StereoSide> SilentSide() const override;
  void SetColourWanted(bool colour) override;

  // Valid after a successful Start().
  const LibcameraStreamInfo& stream_info() const;
  // Number of cameras libcamera reported at the last Start() (0 on a machine without any).
  int cameras_found() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace sh::hal
