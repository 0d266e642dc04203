#include "recog/image/frame.hpp"

#include <algorithm>
#include <cstring>

namespace sh {
namespace {

// Y'CbCr -> R'G'B' in Q14 fixed point: R = Y + cr_r Cr, G = Y - cb_g Cb - cr_g Cr,
// B = Y + cb_b Cb, with Y = y_scale (Y' - y_offset) and Cb, Cr = c_scale (C - 128).
struct YcbcrMatrix {
  int32_t y_scale, y_offset, c_scale;  // Q14 scales; offset in code values
  int32_t cr_r, cb_g, cr_g, cb_b;      // Q14
};

constexpr int32_t Q14(double v) { return static_cast<int32_t>(v * 16384.0 + (v < 0 ? -0.5 : 0.5)); }

// From the luma weights Kr, Kb of the encoding (ITU-R BT.601 / BT.709).
constexpr YcbcrMatrix MakeMatrix(double kr, double kb, bool limited) {
  const double kg = 1.0 - kr - kb;
  return {Q14(limited ? 255.0 / 219.0 : 1.0),
          limited ? 16 : 0,
          Q14(limited ? 255.0 / 224.0 : 1.0),
          Q14(2.0 * (1.0 - kr)),
          Q14(2.0 * kb * (1.0 - kb) / kg),
          Q14(2.0 * kr * (1.0 - kr) / kg),
          Q14(2.0 * (1.0 - kb))};
}

constexpr YcbcrMatrix kMatrices[2][2] = {
    {MakeMatrix(0.299, 0.114, false), MakeMatrix(0.299, 0.114, true)},
    {MakeMatrix(0.2126, 0.0722, false), MakeMatrix(0.2126, 0.0722, true)},
};

const YcbcrMatrix& MatrixOf(const FrameView& f) {
  return kMatrices[f.encoding == YcbcrEncoding::kRec709 ? 1 : 0]
                  [f.range == YcbcrRange::kLimited ? 1 : 0];
}

uint8_t Clamp255(int32_t q14) {
  // Q14 -> integer code value, rounded, clamped to 0..255.
  const int32_t v = (q14 + (1 << 13)) >> 14;
  return static_cast<uint8_t>(std::min(255, std::max(0, v)));
}

Rgb8 ConvertPixel(const YcbcrMatrix& m, uint8_t y, uint8_t cb, uint8_t cr) {
  // Q14 luma, and chroma as Q14 * code values (the products stay below 2^31: 2^16 * 2^8).
  const int32_t yy = m.y_scale * (int32_t{y} - m.y_offset);
  const int32_t b = (m.c_scale * (int32_t{cb} - 128)) >> 7;  // Q7 chroma keeps products in range
  const int32_t r = (m.c_scale * (int32_t{cr} - 128)) >> 7;
  Rgb8 out;
  out.r = Clamp255(yy + ((m.cr_r * r) >> 7));
  out.g = Clamp255(yy - ((m.cb_g * b) >> 7) - ((m.cr_g * r) >> 7));
  out.b = Clamp255(yy + ((m.cb_b * b) >> 7));
  return out;
}

bool PlaneOk(int width, int height, int stride, const void* data, int want_w, int want_h) {
  return data != nullptr && width == want_w && height == want_h && stride >= width;
}

}  // namespace

const char* FrameFormatName(FrameFormat format) {
  switch (format) {
    case FrameFormat::kGray8:
      return "grey";
    case FrameFormat::kRgb888:
      return "RGB888";
    case FrameFormat::kNv12:
      return "NV12";
    case FrameFormat::kYuv420:
      return "YUV420";
  }
  return "unknown";
}

FrameView FrameView::Gray(ConstGrayView image) {
  FrameView f;
  f.format = FrameFormat::kGray8;
  f.luma = image;
  return f;
}

FrameView FrameView::Rgb(ImageView<const Rgb8> image) {
  FrameView f;
  f.format = FrameFormat::kRgb888;
  f.rgb = image;
  return f;
}

FrameView FrameView::Nv12(ConstGrayView y, ImageView<const CbCr8> cbcr, YcbcrEncoding encoding,
                          YcbcrRange range) {
  FrameView f;
  f.format = FrameFormat::kNv12;
  f.luma = y;
  f.cbcr = cbcr;
  f.encoding = encoding;
  f.range = range;
  return f;
}

FrameView FrameView::Yuv420(ConstGrayView y, ConstGrayView cb, ConstGrayView cr,
                            YcbcrEncoding encoding, YcbcrRange range) {
  FrameView f;
  f.format = FrameFormat::kYuv420;
  f.luma = y;
  f.cb = cb;
  f.cr = cr;
  f.encoding = encoding;
  f.range = range;
  return f;
}

Status CheckFrame(const FrameView& f) {
  const int w = f.width(), h = f.height();
  if (w <= 0 || h <= 0) {
    return Status::Error(StatusCode::kInvalidArgument, "%s frame is empty",
                         FrameFormatName(f.format));
  }
  const int cw = (w + 1) / 2, ch = (h + 1) / 2;
  bool ok = true;
  switch (f.format) {
    case FrameFormat::kGray8:
      ok = PlaneOk(w, h, f.luma.stride, f.luma.data, w, h);
      break;
    case FrameFormat::kRgb888:
      ok = PlaneOk(w, h, f.rgb.stride, f.rgb.data, w, h);
      break;
    case FrameFormat::kNv12:
      ok = PlaneOk(w, h, f.luma.stride, f.luma.data, w, h) &&
           PlaneOk(f.cbcr.width, f.cbcr.height, f.cbcr.stride, f.cbcr.data, cw, ch);
      break;
    case FrameFormat::kYuv420:
      ok = PlaneOk(w, h, f.luma.stride, f.luma.data, w, h) &&
           PlaneOk(f.cb.width, f.cb.height, f.cb.stride, f.cb.data, cw, ch) &&
           PlaneOk(f.cr.width, f.cr.height, f.cr.stride, f.cr.data, cw, ch);
      break;
    default:
      return Status::Error(StatusCode::kInvalidArgument, "frame format %d is not supported",
                           static_cast<int>(f.format));
  }
  if (!ok) {
    return Status::Error(StatusCode::kInvalidArgument,
                         "%s frame %dx%d: a plane is missing, has a short stride, or its chroma "
                         "planes are not %dx%d",
                         FrameFormatName(f.format), w, h, cw, ch);
  }
  return Status::Ok();
}

void FrameRowToRgb(const FrameView& f, int y, Rgb8* out) {
  const int w = f.width();
  switch (f.format) {
    case FrameFormat::kGray8: {
      const uint8_t* row = f.luma.row(y);
      for (int x = 0; x < w; ++x) out[x] = {row[x], row[x], row[x]};
      return;
    }
    case FrameFormat::kRgb888:
      std::memcpy(out, f.rgb.row(y), sizeof(Rgb8) * static_cast<size_t>(w));
      return;
    case FrameFormat::kNv12: {
      const YcbcrMatrix& m = MatrixOf(f);
      const uint8_t* row = f.luma.row(y);
      const CbCr8* c = f.cbcr.row(y / 2);
      for (int x = 0; x < w; ++x) out[x] = ConvertPixel(m, row[x], c[x / 2].cb, c[x / 2].cr);
      return;
    }
    case FrameFormat::kYuv420: {
      const YcbcrMatrix& m = MatrixOf(f);
      const uint8_t* row = f.luma.row(y);
      const uint8_t* cb = f.cb.row(y / 2);
      const uint8_t* cr = f.cr.row(y / 2);
      for (int x = 0; x < w; ++x) out[x] = ConvertPixel(m, row[x], cb[x / 2], cr[x / 2]);
      return;
    }
  }
}

Rgb8 FramePixel(const FrameView& f, int x, int y) {
  switch (f.format) {
    case FrameFormat::kGray8: {
      const uint8_t v = f.luma.at(x, y);
      return {v, v, v};
    }
    case FrameFormat::kRgb888:
      return f.rgb.at(x, y);
    case FrameFormat::kNv12: {
      const CbCr8 c = f.cbcr.at(x / 2, y / 2);
      return ConvertPixel(MatrixOf(f), f.luma.at(x, y), c.cb, c.cr);
    }
    case FrameFormat::kYuv420:
      return ConvertPixel(MatrixOf(f), f.luma.at(x, y), f.cb.at(x / 2, y / 2),
                          f.cr.at(x / 2, y / 2));
  }
  return {};
}

bool FrameLuma(const FrameView& f, ConstGrayView* luma) {
  if (f.format == FrameFormat::kRgb888) return false;
  *luma = f.luma;
  return true;
}

Status FrameToGray(const FrameView& f, GrayView out) {
  SH_RETURN_IF_ERROR(CheckFrame(f));
  if (out.empty() || out.width != f.width() || out.height != f.height() || out.stride < out.width) {
    return Status::Error(StatusCode::kInvalidArgument,
                         "grey output is %dx%d but the %s frame is %dx%d", out.width, out.height,
                         FrameFormatName(f.format), f.width(), f.height());
  }
  for (int y = 0; y < out.height; ++y) {
    uint8_t* dst = out.row(y);
    if (f.format == FrameFormat::kRgb888) {
      const Rgb8* src = f.rgb.row(y);
      for (int x = 0; x < out.width; ++x) {
        // BT.601 weights in 8.8 fixed point (77 + 150 + 29 = 256), rounded.
        dst[x] =
            static_cast<uint8_t>((77u * src[x].r + 150u * src[x].g + 29u * src[x].b + 128u) >> 8);
      }
    } else {
      std::memcpy(dst, f.luma.row(y), static_cast<size_t>(out.width));
    }
  }
  return Status::Ok();
}

}  // namespace sh
