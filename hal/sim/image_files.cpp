#include "hal/sim/image_files.hpp"

#include <sys/stat.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>

#include <png.h>

#include "tables/input_file.hpp"

namespace sh::hal {
namespace {

constexpr uint8_t kPngSignature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};

// malloc'd buffer released on scope exit (host-side file handling only).
struct HeapBuffer {
  explicit HeapBuffer(size_t n)
      : data(static_cast<uint8_t*>(std::malloc(n > 0 ? n : 1))), size(n > 0 ? n : 1) {}
  ~HeapBuffer() { std::free(data); }
  HeapBuffer(const HeapBuffer&) = delete;
  HeapBuffer& operator=(const HeapBuffer&) = delete;
  uint8_t* data;
  size_t size;
};

Status CheckSize(const char* what, int width, int height, PixelFormat format, size_t capacity) {
  if (width <= 0 || height <= 0) {
    return Status::Error(StatusCode::kInvalidArgument, "%s: image has zero size (%d x %d)", what,
                         width, height);
  }
  if (width > kMaxSensorWidth || height > kMaxSensorHeight) {
    return Status::Error(StatusCode::kOutOfRange, "%s: image %d x %d exceeds the %d x %d limit",
                         what, width, height, kMaxSensorWidth, kMaxSensorHeight);
  }
  const size_t needed = size_t(width) * size_t(height) * size_t(Channels(format));
  if (needed > capacity) {
    return Status::Error(StatusCode::kResourceExhausted,
                         "%s: %d x %d image needs %zu bytes, buffer holds %zu", what, width, height,
                         needed, capacity);
  }
  return Status::Ok();
}

uint8_t Luma(uint8_t r, uint8_t g, uint8_t b) {
  // BT.601 weights in 8.8 fixed point (77 + 150 + 29 = 256), rounded.
  return static_cast<uint8_t>((77u * r + 150u * g + 29u * b + 128u) >> 8);
}

void StorePixel(uint8_t* out, PixelFormat format, uint8_t r, uint8_t g, uint8_t b) {
  if (format == PixelFormat::kGray8) {
    out[0] = (r == g && g == b) ? r : Luma(r, g, b);
  } else {
    out[0] = r;
    out[1] = g;
    out[2] = b;
  }
}

// libpng's simplified API image, released on scope exit (the library reports errors through
// the structure, without longjmp through our frames).
struct PngImage {
  PngImage() { image.version = PNG_IMAGE_VERSION; }
  ~PngImage() { png_image_free(&image); }
  PngImage(const PngImage&) = delete;
  PngImage& operator=(const PngImage&) = delete;
  png_image image{};
};

uint32_t ReadBe32(const uint8_t* p) {
  return (uint32_t{p[0]} << 24) | (uint32_t{p[1]} << 16) | (uint32_t{p[2]} << 8) | p[3];
}

// ---------------------------------------------------------------------------------------------
// PGM

// The decoder and the size probe refuse plain PGM alike.
Status PlainPgmRefused() {
  return Status::Error(StatusCode::kUnimplemented,
                       "PGM: plain (ASCII, P2) files not supported; use binary P5");
}

bool IsPnmSpace(uint8_t c) {
  return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\v' || c == '\f';
}

// Reads one header number, skipping whitespace and '#' comments before it.
Status PgmHeaderNumber(const uint8_t* data, size_t size, size_t* pos, const char* what,
                       long* value) {
  size_t p = *pos;
  for (;;) {
    while (p < size && IsPnmSpace(data[p])) ++p;
    if (p < size && data[p] == '#') {
      while (p < size && data[p] != '\n') ++p;
      continue;
    }
    break;
  }
  if (p == size) {
    return Status::Error(StatusCode::kDataLoss, "PGM: header truncated before the %s", what);
  }
  long v = 0;
  size_t digits = 0;
  while (p < size && data[p] >= '0' && data[p] <= '9') {
    if (v < 100000000) v = v * 10 + (data[p] - '0');
    ++p;
    ++digits;
  }
  if (digits == 0) {
    return Status::Error(StatusCode::kInvalidArgument, "PGM: %s is not a number", what);
  }
  if (digits > 9) {  // v stopped growing: quote the number as written, never a cut one
    const size_t first = p - digits;
    return Status::Error(StatusCode::kOutOfRange, "PGM: %s %.*s is out of range", what,
                         static_cast<int>(digits < 40 ? digits : 40),
                         reinterpret_cast<const char*>(data + first));
  }
  if (p == size) {
    return Status::Error(StatusCode::kDataLoss, "PGM: header truncated after the %s", what);
  }
  if (!IsPnmSpace(data[p])) {
    return Status::Error(StatusCode::kInvalidArgument, "PGM: %s is followed by '%c'", what,
                         data[p]);
  }
  *pos = p;
  *value = v;
  return Status::Ok();
}

Status WriteFile(const char* path, const uint8_t* data, size_t size) {
  std::FILE* f = std::fopen(path, "wb");
  if (f == nullptr) {
    return Status::Error(StatusCode::kNotFound, "cannot create %s: %s", path, std::strerror(errno));
  }
  const size_t written = std::fwrite(data, 1, size, f);
  const int write_errno = errno;
  if (std::fclose(f) != 0 || written != size) {
    return Status::Error(StatusCode::kUnavailable, "cannot write %s: %s", path,
                         std::strerror(written != size ? write_errno : errno));
  }
  return Status::Ok();
}

}  // namespace

Result<ImageInfo> DecodePgm(const uint8_t* data, size_t size, PixelFormat format, uint8_t* pixels,
                            size_t capacity) {
  if (data == nullptr || size < 2 || data[0] != 'P') {
    return Status::Error(StatusCode::kInvalidArgument, "PGM: missing 'P5' signature");
  }
  if (data[1] == '2') return PlainPgmRefused();
  if (data[1] != '5') {
    return Status::Error(StatusCode::kInvalidArgument,
                         "PGM: signature P%c is not a binary grey map (P5)", data[1]);
  }
  size_t pos = 2;
  if (pos == size || !IsPnmSpace(data[pos])) {
    return Status::Error(StatusCode::kInvalidArgument, "PGM: no whitespace after 'P5'");
  }
  long width = 0, height = 0, maxval = 0;
  SH_RETURN_IF_ERROR(PgmHeaderNumber(data, size, &pos, "width", &width));
  SH_RETURN_IF_ERROR(PgmHeaderNumber(data, size, &pos, "height", &height));
  SH_RETURN_IF_ERROR(PgmHeaderNumber(data, size, &pos, "maximum value", &maxval));
  ++pos;  // exactly one whitespace byte separates the header from the pixels
  if (maxval == 0 || maxval > 65535) {
    return Status::Error(StatusCode::kInvalidArgument, "PGM: invalid maximum value %ld", maxval);
  }
  if (maxval > 255) {
    return Status::Error(StatusCode::kUnimplemented,
                         "PGM: 16-bit samples (maximum value %ld) not supported", maxval);
  }
  if (width > kMaxSensorWidth || height > kMaxSensorHeight) {
    return Status::Error(StatusCode::kOutOfRange, "PGM: image %ld x %ld exceeds the %d x %d limit",
                         width, height, kMaxSensorWidth, kMaxSensorHeight);
  }
  SH_RETURN_IF_ERROR(
      CheckSize("PGM", static_cast<int>(width), static_cast<int>(height), format, capacity));
  const size_t n = size_t(width) * size_t(height);
  if (size - pos < n) {
    return Status::Error(StatusCode::kDataLoss, "PGM: truncated, %zu of %zu pixel bytes present",
                         size - pos, n);
  }
  const uint8_t* src = data + pos;
  const int out_channels = Channels(format);
  for (size_t i = 0; i < n; ++i) {
    // Rescale other ranges to 0..255, rounding; samples above maxval are clamped.
    const long v = src[i] > maxval ? maxval : src[i];
    const uint8_t grey =
        maxval == 255 ? src[i] : static_cast<uint8_t>((v * 255 + maxval / 2) / maxval);
    for (int c = 0; c < out_channels; ++c) pixels[i * out_channels + c] = grey;
  }
  ImageInfo info;
  info.width = static_cast<int>(width);
  info.height = static_cast<int>(height);
  info.file_channels = 1;
  return info;
}

Result<ImageInfo> DecodePng(const uint8_t* data, size_t size, PixelFormat format, uint8_t* pixels,
                            size_t capacity) {
  if (data == nullptr || size < 8 || std::memcmp(data, kPngSignature, 8) != 0) {
    return Status::Error(StatusCode::kInvalidArgument, "PNG: missing PNG signature");
  }
  // Our size limits first, from the IHDR fields (libpng would refuse huge images with its own
  // limits, under another code).
  if (size >= 24 && std::memcmp(data + 12, "IHDR", 4) == 0) {
    const uint32_t w = ReadBe32(data + 16), h = ReadBe32(data + 20);
    if (w > uint32_t(kMaxSensorWidth) || h > uint32_t(kMaxSensorHeight)) {
      return Status::Error(StatusCode::kOutOfRange, "PNG: image %u x %u exceeds the %d x %d limit",
                           w, h, kMaxSensorWidth, kMaxSensorHeight);
    }
  }
  PngImage image;
  if (!png_image_begin_read_from_memory(&image.image, data, size)) {
    return Status::Error(StatusCode::kInvalidArgument, "PNG: %s", image.image.message);
  }
  if (image.image.format & PNG_FORMAT_FLAG_LINEAR) {
    // libpng would convert 16-bit samples to 8-bit sRGB with a gamma curve: not what a camera's
    // raw grey levels mean.
    return Status::Error(StatusCode::kUnimplemented,
                         "PNG: bit depth 16 not supported (8 bits per sample only)");
  }
  const int width = static_cast<int>(image.image.width);
  const int height = static_cast<int>(image.image.height);
  SH_RETURN_IF_ERROR(CheckSize("PNG", width, height, format, capacity));
  // Colour or grey as the file holds it, with alpha kept (straight, not premultiplied, for 8-bit
  // output) so that it can be ignored rather than composited; the grey conversion is ours.
  const bool colour = (image.image.format & PNG_FORMAT_FLAG_COLOR) != 0;
  const bool alpha = (image.image.format & PNG_FORMAT_FLAG_ALPHA) != 0;
  const int file_channels = (colour ? 3 : 1) + (alpha ? 1 : 0);
  image.image.format = colour ? PNG_FORMAT_RGBA : PNG_FORMAT_GA;
  const int read_channels = colour ? 4 : 2;
  HeapBuffer decoded(size_t(width) * size_t(height) * size_t(read_channels));
  if (decoded.data == nullptr) {
    return Status::Error(StatusCode::kResourceExhausted, "PNG: no memory");
  }
  if (!png_image_finish_read(&image.image, nullptr, decoded.data, 0, nullptr)) {
    return Status::Error(StatusCode::kDataLoss, "PNG image data: %s", image.image.message);
  }
  const size_t n = size_t(width) * size_t(height);
  const int out_channels = Channels(format);
  for (size_t i = 0; i < n; ++i) {
    const uint8_t* px = decoded.data + i * size_t(read_channels);
    if (colour) {
      StorePixel(pixels + i * size_t(out_channels), format, px[0], px[1], px[2]);
    } else {
      StorePixel(pixels + i * size_t(out_channels), format, px[0], px[0], px[0]);
    }
  }
  ImageInfo info;
  info.width = width;
  info.height = height;
  // A palette file reports 3 channels (its entries are colours), as RGB.
  info.file_channels = file_channels;
  return info;
}

Result<ImageInfo> DecodeImage(const uint8_t* data, size_t size, PixelFormat format, uint8_t* pixels,
                              size_t capacity) {
  if (data != nullptr && size >= 8 && std::memcmp(data, kPngSignature, 8) == 0) {
    return DecodePng(data, size, format, pixels, capacity);
  }
  if (data != nullptr && size >= 2 && data[0] == 'P') {
    return DecodePgm(data, size, format, pixels, capacity);
  }
  return Status::Error(StatusCode::kInvalidArgument, "image is neither PNG nor PGM");
}

Result<ImageInfo> ImageFileSize(const uint8_t* data, size_t size) {
  ImageInfo info;
  if (data != nullptr && size >= 8 && std::memcmp(data, kPngSignature, 8) == 0) {
    if (size < 24 || std::memcmp(data + 12, "IHDR", 4) != 0) {
      return Status::Error(StatusCode::kDataLoss, "PNG: no IHDR chunk after the signature");
    }
    const uint32_t w = ReadBe32(data + 16);
    const uint32_t h = ReadBe32(data + 20);
    if (w > uint32_t(kMaxSensorWidth) || h > uint32_t(kMaxSensorHeight)) {
      return Status::Error(StatusCode::kOutOfRange, "PNG: image %u x %u exceeds the %d x %d limit",
                           w, h, kMaxSensorWidth, kMaxSensorHeight);
    }
    info.width = static_cast<int>(w);
    info.height = static_cast<int>(h);
    return info;
  }
  if (data != nullptr && size >= 2 && data[0] == 'P' && data[1] == '2') return PlainPgmRefused();
  if (data == nullptr || size < 3 || data[0] != 'P' || data[1] != '5' || !IsPnmSpace(data[2])) {
    return Status::Error(StatusCode::kInvalidArgument, "image is neither PNG nor binary PGM");
  }
  size_t pos = 2;
  long width = 0;
  long height = 0;
  SH_RETURN_IF_ERROR(PgmHeaderNumber(data, size, &pos, "width", &width));
  SH_RETURN_IF_ERROR(PgmHeaderNumber(data, size, &pos, "height", &height));
  if (width > kMaxSensorWidth || height > kMaxSensorHeight) {
    return Status::Error(StatusCode::kOutOfRange, "PGM: image %ld x %ld exceeds the %d x %d limit",
                         width, height, kMaxSensorWidth, kMaxSensorHeight);
  }
  info.width = static_cast<int>(width);
  info.height = static_cast<int>(height);
  return info;
}

Result<ImageInfo> ReadImageFile(const char* path, PixelFormat format, uint8_t* pixels,
                                size_t capacity) {
  InputFile file;
  SH_RETURN_IF_ERROR(file.Open(path, "image", kMaxImageFileBytes));
  HeapBuffer buffer{file.size() == 0 ? kMaxImageFileBytes : file.size()};
  if (buffer.data == nullptr) {
    return Status::Error(StatusCode::kResourceExhausted, "%s: out of memory", path);
  }
  size_t got = 0;
  SH_RETURN_IF_ERROR(file.ReadAll(reinterpret_cast<char*>(buffer.data), buffer.size, &got));
  Result<ImageInfo> info = DecodeImage(buffer.data, got, format, pixels, capacity);
  if (!info.ok()) return info.status().WithContext("%s", path);
  return info;
}

size_t EncodedPngBound(int width, int height, int channels) {
  png_image image{};
  image.version = PNG_IMAGE_VERSION;
  image.width = static_cast<png_uint_32>(width);
  image.height = static_cast<png_uint_32>(height);
  image.format = channels == 1 ? PNG_FORMAT_GRAY : PNG_FORMAT_RGB;
  return PNG_IMAGE_PNG_SIZE_MAX(image);
}

Result<size_t> EncodePng(const uint8_t* pixels, int width, int height, int stride_bytes,
                         int channels, uint8_t* out, size_t capacity) {
  if (width <= 0 || height <= 0 || width > kMaxSensorWidth || height > kMaxSensorHeight) {
    return Status::Error(StatusCode::kOutOfRange, "PNG: cannot encode a %d x %d image", width,
                         height);
  }
  if (channels != 1 && channels != 3) {
    return Status::Error(StatusCode::kInvalidArgument, "PNG: cannot encode %d channels", channels);
  }
  const size_t row_bytes = size_t(width) * size_t(channels);
  if (stride_bytes < 0 || size_t(stride_bytes) < row_bytes) {
    return Status::Error(StatusCode::kInvalidArgument, "PNG: stride %d below row size %zu",
                         stride_bytes, row_bytes);
  }
  if (capacity < EncodedPngBound(width, height, channels)) {
    return Status::Error(StatusCode::kResourceExhausted,
                         "PNG: output buffer of %zu bytes below the bound of %zu", capacity,
                         EncodedPngBound(width, height, channels));
  }
  PngImage image;
  image.image.width = static_cast<png_uint_32>(width);
  image.image.height = static_cast<png_uint_32>(height);
  image.image.format = channels == 1 ? PNG_FORMAT_GRAY : PNG_FORMAT_RGB;
  png_alloc_size_t size = capacity;
  // The stride is in components, which are bytes here.
  if (!png_image_write_to_memory(&image.image, out, &size, 0, pixels, stride_bytes, nullptr)) {
    return Status::Error(StatusCode::kInternal, "PNG: %s", image.image.message);
  }
  return size_t(size);
}

Status WritePgm(const char* path, ConstGrayView image) {
  if (image.empty()) return Status::Error(StatusCode::kInvalidArgument, "PGM: empty image");
  char header[64];
  const int n =
      std::snprintf(header, sizeof(header), "P5\n%d %d\n255\n", image.width, image.height);
  const size_t size = size_t(n) + size_t(image.width) * size_t(image.height);
  HeapBuffer buffer(size);
  if (buffer.data == nullptr)
    return Status::Error(StatusCode::kResourceExhausted, "PGM: no memory");
  std::memcpy(buffer.data, header, size_t(n));
  for (int y = 0; y < image.height; ++y) {
    std::memcpy(buffer.data + n + size_t(y) * size_t(image.width), image.row(y),
                size_t(image.width));
  }
  return WriteFile(path, buffer.data, size);
}

namespace {
Status WritePngFile(const char* path, const uint8_t* pixels, int width, int height,
                    int stride_bytes, int channels) {
  if (pixels == nullptr || width <= 0 || height <= 0) {
    return Status::Error(StatusCode::kInvalidArgument, "PNG: empty image for %s", path);
  }
  if (width > kMaxPngWriteSide || height > kMaxPngWriteSide) {
    return Status::Error(StatusCode::kOutOfRange, "PNG: cannot write a %d x %d image", width,
                         height);
  }
  if (stride_bytes < width * channels) {
    return Status::Error(StatusCode::kInvalidArgument, "PNG: stride %d below row size %d",
                         stride_bytes, width * channels);
  }
  PngImage image;
  image.image.width = static_cast<png_uint_32>(width);
  image.image.height = static_cast<png_uint_32>(height);
  image.image.format = channels == 1 ? PNG_FORMAT_GRAY : PNG_FORMAT_RGB;
  // Recorded pairs and rendered sets are written once per frame and read back by our own tools:
  // libpng's fast setting takes a half to a quarter of the default deflate time for files up to a
  // quarter larger, so the recorder's writer thread keeps up with more triggers.
  image.image.flags = PNG_IMAGE_FLAG_FAST;
  if (!png_image_write_to_file(&image.image, path, 0, pixels, stride_bytes, nullptr)) {
    return Status::Error(StatusCode::kUnavailable, "cannot write %s: %s", path,
                         image.image.message);
  }
  return Status::Ok();
}
}  // namespace

Status WritePng(const char* path, ConstGrayView image) {
  return WritePngFile(path, image.data, image.width, image.height, image.stride, 1);
}

Status WritePngRgb(const char* path, const uint8_t* rgb, int width, int height, int stride_bytes) {
  return WritePngFile(path, rgb, width, height, stride_bytes, 3);
}

}  // namespace sh::hal
