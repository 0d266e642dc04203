// Image files for the simulator's recorded-pair camera and the host tools: binary PGM (P5, 8-bit,
// read and written here) and PNG through Debian's libpng (8-bit grey, grey+alpha, RGB, RGBA,
// palette, interlaced or not; 16-bit refused). Decoders read from memory into the caller's buffer
// and refuse anything they cannot represent with a Status; they never read or write out of
// bounds.
#pragma once

#include <cstddef>
#include <cstdint>

#include "recog/base/status.hpp"
#include "recog/image/image.hpp"

namespace sh::hal {

// Largest file ReadImageFile loads (a 2592 x 2048 RGBA PNG stored uncompressed is ~21 MB).
inline constexpr size_t kMaxImageFileBytes = 64u << 20;

// Layout of decoded pixels: rows packed (stride = width * channels), top row first.
enum class PixelFormat : uint8_t {
  kGray8 = 1,  // colour converted with ITU-R BT.601 luma weights; alpha ignored
  kRgb8 = 3,   // grey replicated into R, G and B; alpha ignored
};
inline int Channels(PixelFormat f) { return static_cast<int>(f); }

struct ImageInfo {
  int width = 0;
  int height = 0;
  int file_channels = 0;  // 1 grey, 2 grey+alpha, 3 RGB or palette, 4 RGBA
};

// Decoders. `pixels` must hold width * height * Channels(format) bytes (else kResourceExhausted);
// images larger than kMaxSensorWidth x kMaxSensorHeight are refused with kOutOfRange.
Result<ImageInfo> DecodePgm(const uint8_t* data, size_t size, PixelFormat format, uint8_t* pixels,
                            size_t capacity);
Result<ImageInfo> DecodePng(const uint8_t* data, size_t size, PixelFormat format, uint8_t* pixels,
                            size_t capacity);
// PNG or PGM, chosen by the file's signature.
Result<ImageInfo> DecodeImage(const uint8_t* data, size_t size, PixelFormat format, uint8_t* pixels,
                              size_t capacity);
// The width and height a PNG (its IHDR chunk) or binary PGM (its header) declares, without
// decoding (file_channels 0); kInvalidArgument or kDataLoss when the header is not one.
Result<ImageInfo> ImageFileSize(const uint8_t* data, size_t size);
Result<ImageInfo> ReadImageFile(const char* path, PixelFormat format, uint8_t* pixels,
                                size_t capacity);

// Encoders into memory. EncodedPngBound() is always enough capacity.
size_t EncodedPngBound(int width, int height, int channels);
Result<size_t> EncodePng(const uint8_t* pixels, int width, int height, int stride_bytes,
                         int channels, uint8_t* out, size_t capacity);

// Writers (grey PNG/PGM from a view; RGB PNG from packed or strided 3-byte pixels). PNG files
// may be larger than a camera frame (side-by-side overlays), up to kMaxPngWriteSide a side.
inline constexpr int kMaxPngWriteSide = 1 << 15;
Status WritePgm(const char* path, ConstGrayView image);
Status WritePng(const char* path, ConstGrayView image);
Status WritePngRgb(const char* path, const uint8_t* rgb, int width, int height, int stride_bytes);

}  // namespace sh::hal
