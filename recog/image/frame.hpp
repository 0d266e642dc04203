// A camera frame in any of the formats the cameras deliver: 8-bit grey, interleaved RGB, or
// Y'CbCr 4:2:0 (NV12 with interleaved chroma, or I420 with planar chroma). Non-owning, like
// ImageView: the planes belong to whoever captured or decoded the frame.
//
// The grey path reads the luma plane of a Y'CbCr frame in place (zero-copy); an RGB frame has
// no luma plane and is converted (FrameToGray). The colour paths read R'G'B' rows through
// FrameRowToRgb whatever the format.
#pragma once

#include <cstdint>

#include "recog/base/status.hpp"
#include "recog/image/image.hpp"

namespace sh {

enum class FrameFormat : uint8_t {
  kGray8,   // one 8-bit plane
  kRgb888,  // interleaved R, G, B bytes
  kNv12,    // Y plane, then Cb/Cr pairs at half resolution in both axes
  kYuv420,  // Y plane, Cb plane and Cr plane at half resolution in both axes (I420)
};

const char* FrameFormatName(FrameFormat format);

// How Y'CbCr values map to R'G'B' (libcamera's ColorSpace YcbcrEncoding and Range).
enum class YcbcrEncoding : uint8_t { kRec601, kRec709 };
enum class YcbcrRange : uint8_t {
  kFull,     // Y' and Cb/Cr over 0..255 (JPEG, sYCC)
  kLimited,  // Y' over 16..235, Cb/Cr over 16..240 (video)
};

// One Cb/Cr pair of an NV12 chroma plane.
struct CbCr8 {
  uint8_t cb = 128, cr = 128;
};
static_assert(sizeof(CbCr8) == 2, "CbCr8 must match interleaved NV12 chroma memory");

struct FrameView {
  FrameFormat format = FrameFormat::kGray8;
  ConstGrayView luma;           // kGray8: the image; kNv12, kYuv420: the Y plane
  ImageView<const Rgb8> rgb;    // kRgb888
  ImageView<const CbCr8> cbcr;  // kNv12: ceil(w/2) x ceil(h/2) pairs
  ConstGrayView cb, cr;         // kYuv420: ceil(w/2) x ceil(h/2) each
  YcbcrEncoding encoding = YcbcrEncoding::kRec601;
  YcbcrRange range = YcbcrRange::kFull;

  static FrameView Gray(ConstGrayView image);
  static FrameView Rgb(ImageView<const Rgb8> image);
  static FrameView Nv12(ConstGrayView y, ImageView<const CbCr8> cbcr, YcbcrEncoding encoding,
                        YcbcrRange range);
  static FrameView Yuv420(ConstGrayView y, ConstGrayView cb, ConstGrayView cr,
                          YcbcrEncoding encoding, YcbcrRange range);

  int width() const { return format == FrameFormat::kRgb888 ? rgb.width : luma.width; }
  int height() const { return format == FrameFormat::kRgb888 ? rgb.height : luma.height; }
  bool has_colour() const { return format != FrameFormat::kGray8; }
};

// Checks that the planes the format needs are present and consistent: non-empty, strides at
// least the widths, chroma planes of half the luma size (rounded up).
Status CheckFrame(const FrameView& frame);

// Row y of the frame as R'G'B' (grey replicated; Y'CbCr converted with the frame's encoding and
// range, chroma of the 2 x 2 block). `out` holds width() pixels. The frame must pass CheckFrame.
void FrameRowToRgb(const FrameView& frame, int y, Rgb8* out);

// One pixel as R'G'B' (as FrameRowToRgb converts it). (x, y) must lie inside the frame.
Rgb8 FramePixel(const FrameView& frame, int x, int y);

// The luma plane read in place: true for grey and Y'CbCr frames, false for RGB (convert it with
// FrameToGray).
bool FrameLuma(const FrameView& frame, ConstGrayView* luma);

// Grey image of the frame: the luma plane copied, or RGB weighted with the BT.601 luma weights
// in 8.8 fixed point (77 R + 150 G + 29 B, rounded), as the image decoders do. `out` must have
// the frame's size.
Status FrameToGray(const FrameView& frame, GrayView out);

}  // namespace sh
