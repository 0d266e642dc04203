// Plays back recorded stereo pairs from a directory as a StereoCamera.
//
// Layouts (detected in this order):
//   <dir>/left/<name>.png   with <dir>/right/<name>.png
//   <dir>/left_<key>.png    with <dir>/right_<key>.png   ("left<key>"/"left-<key>" also accepted)
//   <dir>/<key>/left.png    with <dir>/<key>/right.png   (recorded scenes: calib.yaml beside the
//                                                        scene folders; firmware recordings)
// Pairs play in natural order of <name>/<key> (numbers compare by value: 2 before 10). Files are
// PNG or binary PGM (.png/.pgm, decoded by hal/sim/image_files; colour is converted to grey);
// other files are ignored. All frames must have the size of the first readable pair; a left file
// without its right partner (or the reverse) makes Start() fail naming it.
//
// Images larger than a pipeline frame (up to kMaxSensorWidth x kMaxSensorHeight) are binned by
// BinFactorFor() into frames that fit, as a binning sensor would deliver them; the calibration
// of the full sensor is scaled to them where it is used (recog/camera/binning.hpp).
//
// Memory: Start() allocates one file buffer (the largest file's size); the first readable pair is
// decoded into two buffers of its size (not kMaxImagePixels), freed once it has set the frame
// size, or kept for a binned recording, whose images are decoded there and binned into frames.
// Playback reads each file into the file buffer and decodes it straight into the camera's frame
// without further allocation; a later frame larger than the first pair is refused by name.
//
// Timestamps are synthetic (first_timestamp_ns + n * frame_period_ns on both sides) and go
// through the same pairing as live cameras. Per-frame problems (truncated or corrupt file,
// left/right sizes differ, size differs from the recording) make that Capture() return a clear
// Status and count an error; the next Capture() continues with the next pair. After the last
// pair Capture() returns kOutOfRange ("end of recording") unless `loop` is set.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "hal/camera.hpp"
#include "hal/sim/sim_camera.hpp"
#include "hal/sim/sim_camera_source.hpp"

namespace sh::hal {

struct DirectoryCameraConfig {
  std::string directory;
  bool loop = false;
  int64_t frame_period_ns = 33'333'333;
  int64_t first_timestamp_ns = 1'000'000'000;
  PairingConfig pairing;
};

// The FrameSource half, usable on its own (e.g. behind a SimCamera with fault injection).
class DirectoryFrameSource final : public FrameSource {
 public:
  DirectoryFrameSource(std::string directory, bool loop);

  // Scans the directory, allocates the file list and buffers, sizes the frames from the first
  // readable pair.
  Status Open(int* width, int* height) override;
  Status Render(uint64_t frame_index, GrayView left, GrayView right) override;

  size_t frame_count() const { return pairs_.size(); }
  // Path of the left file of pair i (for tools that print what they play).
  const std::string& left_path(size_t i) const { return pairs_[i].left; }

 private:
  struct PathPair {
    std::string key;
    std::string left;
    std::string right;
  };
  struct Decoded {
    int width = 0;
    int height = 0;
  };
  Status Scan();
  // One file buffer of the largest file's size.
  Status AllocateFileBuffer();
  // One decode buffer per side of width x height pixels (the recording's first pair).
  Status AllocateDecodeBuffers(int width, int height);
  // Decode buffers for the larger of the pair's two images (read from the files' headers).
  Status AllocateDecodeBuffersFor(const PathPair& pair);
  // Reads `path` into the file buffer; *size is the file's size.
  Status ReadFile(int side, const std::string& path, size_t* size);
  // Reads `path` into the file buffer and decodes it as grey, rows packed, into `pixels`
  // (decode_capacity_ bytes); a frame larger than that is kInvalidArgument (as a frame of another
  // size), naming both sizes; kOutOfRange stays the end of the recording.
  Status Decode(int side, const std::string& path, uint8_t* pixels, Decoded* out);

  std::string directory_;
  bool loop_;
  std::vector<PathPair> pairs_;
  std::unique_ptr<uint8_t[]> file_buffer_;
  size_t file_capacity_ = 0;
  std::unique_ptr<uint8_t[]> decode_[2];  // decode_capacity_ pixels each, during Open() only
  size_t decode_capacity_ = 0;            // pixels of a frame (of the first pair, after Open())
  int width_ = 0;                         // of the recording's images
  int height_ = 0;
  int bin_ = 1;  // BinFactorFor(width_, height_): larger images are binned into the frames
  int frame_width_ = 0;
  int frame_height_ = 0;
};

class DirectoryCamera final : public StereoCamera {
 public:
  explicit DirectoryCamera(const DirectoryCameraConfig& config);

  Status Start() override { return camera_.Start(); }
  Status Stop() override { return camera_.Stop(); }
  Status Capture(StereoFrame* out, int timeout_ms) override {
    return camera_.Capture(out, timeout_ms);
  }
  void Release() override { camera_.Release(); }
  CameraStats stats() const override { return camera_.stats(); }

  size_t frame_count() const { return source_.frame_count(); }

 private:
  static SimCameraConfig MakeSimConfig(const DirectoryCameraConfig& config);

  DirectoryFrameSource source_;
  SimCamera camera_;
};

}  // namespace sh::hal
