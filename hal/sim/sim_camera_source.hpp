// Where simulated stereo frames come from: a renderer, a recording on disk, a test pattern.
//
// SimCamera owns the buffers and calls the source once per frame; the source only fills them.
#pragma once

#include <cstdint>

#include "recog/base/status.hpp"
#include "recog/image/frame.hpp"
#include "recog/image/image.hpp"

namespace sh::hal {

// The planes of one NV12 frame a colour source fills: Y at full size, Cb/Cr pairs at half size
// (rounded up) in both axes, BT.601 full range.
struct Nv12Target {
  GrayView y;
  ImageView<CbCr8> cbcr;
};

class FrameSource {
 public:
  virtual ~FrameSource() = default;

  // Called by SimCamera::Start() before any frame: reports the size of every frame (both sides
  // equal). May allocate (file lists, render scenes); Render() must not.
  virtual Status Open(int* width, int* height) = 0;

  // Fills both views (each width x height from Open()) with frame `frame_index` (0, 1, 2, ...).
  // Errors are per frame: the camera counts them, reports them from Capture() and asks for the
  // next frame on the following call. kOutOfRange means the source has no more frames; the
  // camera then reports end of stream without counting an error.
  virtual Status Render(uint64_t frame_index, GrayView left, GrayView right) = 0;

  // The format of the frames, known after Open(): kGray8 (Render) or kNv12 (RenderNv12).
  virtual FrameFormat format() const { return FrameFormat::kGray8; }
  // Fills both frames' planes with frame `frame_index`, as Render() does, for a kNv12 source.
  virtual Status RenderNv12(uint64_t frame_index, const Nv12Target& left, const Nv12Target& right) {
    return Status::Error(StatusCode::kUnimplemented, "this frame source renders grey frames");
  }
};

}  // namespace sh::hal
