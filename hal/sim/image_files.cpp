#include "hal/sim/image_files.hpp"

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>

#include "hal/sim/deflate.hpp"
#include "hal/sim/inflate.hpp"
#include "recog/base/crc32.hpp"

namespace sh::hal {
namespace {

constexpr uint8_t kPngSignature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
constexpr int kMaxPngChannels = 4;
constexpr size_t kMaxRowBytes = size_t{kMaxImageWidth} * kMaxPngChannels;

// malloc'd buffer released on scope exit (host-side file handling only).
struct HeapBuffer {
  explicit HeapBuffer(size_t n) : data(static_cast<uint8_t*>(std::malloc(n > 0 ? n : 1))) {}
  ~HeapBuffer() { std::free(data); }
  HeapBuffer(const HeapBuffer&) = delete;
  HeapBuffer& operator=(const HeapBuffer&) = delete;
  uint8_t* data;
};

Status CheckSize(const char* what, int width, int height, PixelFormat format, size_t capacity) {
  if (width <= 0 || height <= 0) {
    return Status::Error(StatusCode::kInvalidArgument, "%s: image has zero size (%d x %d)", what,
                         width, height);
  }
  if (width > kMaxImageWidth || height > kMaxImageHeight) {
    return Status::Error(StatusCode::kOutOfRange, "%s: image %d x %d exceeds the %d x %d limit",
                         what, width, height, kMaxImageWidth, kMaxImageHeight);
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

uint32_t ReadBe32(const uint8_t* p) {
  return (uint32_t{p[0]} << 24) | (uint32_t{p[1]} << 16) | (uint32_t{p[2]} << 8) | p[3];
}

void WriteBe32(uint8_t* p, uint32_t v) {
  p[0] = static_cast<uint8_t>(v >> 24);
  p[1] = static_cast<uint8_t>(v >> 16);
  p[2] = static_cast<uint8_t>(v >> 8);
  p[3] = static_cast<uint8_t>(v);
}

// ---------------------------------------------------------------------------------------------
// PGM

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

// ---------------------------------------------------------------------------------------------
// PNG

struct PngHeader {
  int width = 0, height = 0;
  int color_type = 0;
  int channels = 0;  // samples per pixel in the file
  int palette_size = 0;
  uint8_t palette[256][3] = {};
};

// Walks the consecutive IDAT chunks as the pieces of one zlib stream.
class IdatSource final : public ByteSource {
 public:
  IdatSource(const uint8_t* data, size_t size, size_t first_chunk)
      : data_(data), size_(size), next_(first_chunk) {}
  size_t Next(const uint8_t** piece) override {
    // Chunk framing and CRCs were verified before decoding started.
    if (done_ || next_ + 12 > size_ || std::memcmp(data_ + next_ + 4, "IDAT", 4) != 0) {
      done_ = true;
      return 0;
    }
    const size_t length = ReadBe32(data_ + next_);
    *piece = data_ + next_ + 8;
    next_ += 12 + length;
    return length;
  }

 private:
  const uint8_t* data_;
  size_t size_;
  size_t next_;
  bool done_ = false;
};

uint8_t Paeth(int a, int b, int c) {
  const int p = a + b - c;
  const int pa = std::abs(p - a), pb = std::abs(p - b), pc = std::abs(p - c);
  if (pa <= pb && pa <= pc) return static_cast<uint8_t>(a);
  if (pb <= pc) return static_cast<uint8_t>(b);
  return static_cast<uint8_t>(c);
}

// Undoes the per-row filters and converts finished rows into the caller's format.
class PngRowSink final : public ByteSink {
 public:
  PngRowSink(const PngHeader& header, PixelFormat format, uint8_t* pixels)
      : header_(header),
        format_(format),
        pixels_(pixels),
        row_bytes_(size_t(header.width) * size_t(header.channels)) {}

  Status Write(const uint8_t* data, size_t size) override {
    for (size_t i = 0; i < size; ++i) {
      if (row_ == header_.height) {
        return Status::Error(StatusCode::kInvalidArgument, "PNG: image data is longer than %d rows",
                             header_.height);
      }
      if (filled_ < 0) {
        filter_ = data[i];
        if (filter_ > 4) {
          return Status::Error(StatusCode::kInvalidArgument, "PNG: row %d has filter type %d", row_,
                               filter_);
        }
        filled_ = 0;
        continue;
      }
      cur_[filled_++] = data[i];
      if (size_t(filled_) == row_bytes_) SH_RETURN_IF_ERROR(FinishRow());
    }
    return Status::Ok();
  }

  int rows_done() const { return row_; }

 private:
  Status FinishRow() {
    const int bpp = header_.channels;  // bytes per pixel at 8 bits per sample
    for (size_t x = 0; x < row_bytes_; ++x) {
      const int a = x >= size_t(bpp) ? cur_[x - bpp] : 0;
      const int b = prev_[x];
      const int c = x >= size_t(bpp) ? prev_[x - bpp] : 0;
      int predicted = 0;
      switch (filter_) {
        case 0:
          predicted = 0;
          break;
        case 1:
          predicted = a;
          break;
        case 2:
          predicted = b;
          break;
        case 3:
          predicted = (a + b) >> 1;
          break;
        case 4:
          predicted = Paeth(a, b, c);
          break;
      }
      cur_[x] = static_cast<uint8_t>(cur_[x] + predicted);
    }
    const int out_channels = Channels(format_);
    uint8_t* out = pixels_ + size_t(row_) * size_t(header_.width) * size_t(out_channels);
    for (int x = 0; x < header_.width; ++x, out += out_channels) {
      const uint8_t* s = cur_ + size_t(x) * size_t(bpp);
      switch (header_.color_type) {
        case 0:  // grey
        case 4:  // grey + alpha
          StorePixel(out, format_, s[0], s[0], s[0]);
          break;
        case 2:  // RGB
        case 6:  // RGBA
          StorePixel(out, format_, s[0], s[1], s[2]);
          break;
        case 3:  // palette
          if (s[0] >= header_.palette_size) {
            return Status::Error(StatusCode::kInvalidArgument,
                                 "PNG: palette index %d out of range (%d entries)", s[0],
                                 header_.palette_size);
          }
          StorePixel(out, format_, header_.palette[s[0]][0], header_.palette[s[0]][1],
                     header_.palette[s[0]][2]);
          break;
      }
    }
    std::memcpy(prev_, cur_, row_bytes_);
    filled_ = -1;
    ++row_;
    return Status::Ok();
  }

  const PngHeader& header_;
  PixelFormat format_;
  uint8_t* pixels_;
  size_t row_bytes_;
  int row_ = 0;
  int filled_ = -1;  // -1: expecting the filter-type byte of the next row
  int filter_ = 0;
  uint8_t prev_[kMaxRowBytes] = {};  // the row above the first row is zeros
  uint8_t cur_[kMaxRowBytes] = {};
};

Status ParseIhdr(const uint8_t* d, uint32_t length, PngHeader* h) {
  if (length != 13) {
    return Status::Error(StatusCode::kInvalidArgument, "PNG: IHDR has %u bytes, expected 13",
                         length);
  }
  const uint32_t w = ReadBe32(d), ht = ReadBe32(d + 4);
  const int depth = d[8];
  h->color_type = d[9];
  if (w == 0 || ht == 0) {
    return Status::Error(StatusCode::kInvalidArgument, "PNG: image has zero size (%u x %u)", w, ht);
  }
  if (w > uint32_t(kMaxImageWidth) || ht > uint32_t(kMaxImageHeight)) {
    return Status::Error(StatusCode::kOutOfRange, "PNG: image %u x %u exceeds the %d x %d limit", w,
                         ht, kMaxImageWidth, kMaxImageHeight);
  }
  h->width = static_cast<int>(w);
  h->height = static_cast<int>(ht);
  switch (h->color_type) {
    case 0:
      h->channels = 1;
      break;
    case 2:
      h->channels = 3;
      break;
    case 3:
      h->channels = 1;
      break;
    case 4:
      h->channels = 2;
      break;
    case 6:
      h->channels = 4;
      break;
    default:
      return Status::Error(StatusCode::kInvalidArgument, "PNG: invalid colour type %d",
                           h->color_type);
  }
  if (depth != 8) {
    return Status::Error(StatusCode::kUnimplemented,
                         "PNG: bit depth %d not supported (8 bits per sample only)", depth);
  }
  if (d[10] != 0 || d[11] != 0) {
    return Status::Error(StatusCode::kInvalidArgument,
                         "PNG: unknown compression (%d) or filter method (%d)", d[10], d[11]);
  }
  if (d[12] != 0) {
    return Status::Error(StatusCode::kUnimplemented, "PNG: interlaced images not supported");
  }
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

size_t PngChunk(uint8_t* out, const char* type, const uint8_t* data, uint32_t length) {
  WriteBe32(out, length);
  std::memcpy(out + 4, type, 4);
  if (length > 0 && data != out + 8) std::memmove(out + 8, data, length);
  WriteBe32(out + 8 + length, Crc32(out + 4, 4 + size_t{length}));
  return 12 + size_t{length};
}

}  // namespace

Result<ImageInfo> DecodePgm(const uint8_t* data, size_t size, PixelFormat format, uint8_t* pixels,
                            size_t capacity) {
  if (data == nullptr || size < 2 || data[0] != 'P') {
    return Status::Error(StatusCode::kInvalidArgument, "PGM: missing 'P5' signature");
  }
  if (data[1] == '2') {
    return Status::Error(StatusCode::kUnimplemented,
                         "PGM: plain (ASCII, P2) files not supported; use binary P5");
  }
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
  if (width > kMaxImageWidth || height > kMaxImageHeight) {
    return Status::Error(StatusCode::kOutOfRange, "PGM: image %ld x %ld exceeds the %d x %d limit",
                         width, height, kMaxImageWidth, kMaxImageHeight);
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
  PngHeader header;
  size_t pos = 8;
  size_t first_idat = 0;
  bool seen_ihdr = false, seen_iend = false, idat_ended = false;
  // Pass 1: frame every chunk, verify CRCs, read the header and palette, locate the data.
  while (!seen_iend) {
    if (size - pos < 12) {
      return Status::Error(StatusCode::kDataLoss, "PNG: truncated at byte %zu (no IEND chunk)",
                           pos);
    }
    const uint32_t length = ReadBe32(data + pos);
    const uint8_t* type = data + pos + 4;
    for (int i = 0; i < 4; ++i) {
      const bool letter = (type[i] >= 'A' && type[i] <= 'Z') || (type[i] >= 'a' && type[i] <= 'z');
      if (!letter) {
        return Status::Error(StatusCode::kInvalidArgument, "PNG: invalid chunk type at byte %zu",
                             pos);
      }
    }
    if (length > 0x7fffffffu || size - pos - 12 < length) {
      return Status::Error(StatusCode::kDataLoss, "PNG: chunk %.4s of %u bytes is truncated",
                           reinterpret_cast<const char*>(type), length);
    }
    const uint8_t* body = type + 4;
    const uint32_t stored_crc = ReadBe32(body + length);
    const uint32_t crc = Crc32(type, 4 + size_t{length});
    if (crc != stored_crc) {
      return Status::Error(StatusCode::kDataLoss, "PNG: CRC mismatch in chunk %.4s",
                           reinterpret_cast<const char*>(type));
    }
    const bool is_idat = std::memcmp(type, "IDAT", 4) == 0;
    if (!seen_ihdr && std::memcmp(type, "IHDR", 4) != 0) {
      return Status::Error(StatusCode::kInvalidArgument, "PNG: first chunk is not IHDR");
    }
    if (std::memcmp(type, "IHDR", 4) == 0) {
      if (seen_ihdr) return Status::Error(StatusCode::kInvalidArgument, "PNG: second IHDR chunk");
      SH_RETURN_IF_ERROR(ParseIhdr(body, length, &header));
      seen_ihdr = true;
    } else if (std::memcmp(type, "PLTE", 4) == 0) {
      if (length % 3 != 0 || length == 0 || length > 768) {
        return Status::Error(StatusCode::kInvalidArgument, "PNG: PLTE chunk of %u bytes", length);
      }
      header.palette_size = static_cast<int>(length / 3);
      std::memcpy(header.palette, body, length);
    } else if (is_idat) {
      if (idat_ended) {
        return Status::Error(StatusCode::kInvalidArgument, "PNG: IDAT chunks are not consecutive");
      }
      if (first_idat == 0) first_idat = pos;
    } else if (std::memcmp(type, "IEND", 4) == 0) {
      seen_iend = true;
    } else if (type[0] >= 'A' && type[0] <= 'Z') {
      return Status::Error(StatusCode::kUnimplemented, "PNG: unknown critical chunk %.4s",
                           reinterpret_cast<const char*>(type));
    }
    if (first_idat != 0 && !is_idat) idat_ended = true;
    pos += 12 + size_t{length};
  }
  if (first_idat == 0) return Status::Error(StatusCode::kDataLoss, "PNG: no IDAT chunk");
  if (header.color_type == 3 && header.palette_size == 0) {
    return Status::Error(StatusCode::kInvalidArgument, "PNG: palette image without PLTE chunk");
  }
  SH_RETURN_IF_ERROR(CheckSize("PNG", header.width, header.height, format, capacity));

  // Pass 2: decompress and unfilter straight into the caller's buffer.
  IdatSource source(data, size, first_idat);
  PngRowSink sink(header, format, pixels);
  const Status inflated = ZlibInflate(source, sink);
  if (!inflated.ok()) {
    return Status::Error(inflated.code(), "PNG image data: %s", inflated.message());
  }
  if (sink.rows_done() != header.height) {
    return Status::Error(StatusCode::kDataLoss, "PNG: image data ends after %d of %d rows",
                         sink.rows_done(), header.height);
  }
  ImageInfo info;
  info.width = header.width;
  info.height = header.height;
  info.file_channels = header.color_type == 3 ? 3 : header.channels;
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

Result<ImageInfo> ReadImageFile(const char* path, PixelFormat format, uint8_t* pixels,
                                size_t capacity) {
  std::FILE* f = std::fopen(path, "rb");
  if (f == nullptr) {
    return Status::Error(StatusCode::kNotFound, "cannot open %s: %s", path, std::strerror(errno));
  }
  long length = -1;
  if (std::fseek(f, 0, SEEK_END) == 0) length = std::ftell(f);
  if (length < 0 || std::fseek(f, 0, SEEK_SET) != 0) {
    std::fclose(f);
    return Status::Error(StatusCode::kUnavailable, "cannot determine the size of %s", path);
  }
  if (size_t(length) > kMaxImageFileBytes) {
    std::fclose(f);
    return Status::Error(StatusCode::kOutOfRange, "%s: %ld bytes is larger than the %zu limit",
                         path, length, kMaxImageFileBytes);
  }
  HeapBuffer buffer{size_t(length)};
  if (buffer.data == nullptr) {
    std::fclose(f);
    return Status::Error(StatusCode::kResourceExhausted, "%s: out of memory", path);
  }
  const size_t got = std::fread(buffer.data, 1, size_t(length), f);
  std::fclose(f);
  if (got != size_t(length)) {
    return Status::Error(StatusCode::kDataLoss, "%s: short read (%zu of %ld bytes)", path, got,
                         length);
  }
  Result<ImageInfo> info = DecodeImage(buffer.data, got, format, pixels, capacity);
  if (!info.ok()) {
    return Status::Error(info.status().code(), "%s: %s", path, info.status().message());
  }
  return info;
}

size_t EncodedPngBound(int width, int height, int channels) {
  const size_t raw = size_t(height) * (1 + size_t(width) * size_t(channels));
  return 8 + (12 + 13) + 12 + ZlibDeflateBound(raw) + 12;
}

Result<size_t> EncodePng(const uint8_t* pixels, int width, int height, int stride_bytes,
                         int channels, uint8_t* out, size_t capacity) {
  if (width <= 0 || height <= 0 || width > kMaxImageWidth || height > kMaxImageHeight) {
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
  // Filter each row with the filter minimising the sum of |residual| (the usual heuristic).
  const size_t raw_size = size_t(height) * (1 + row_bytes);
  HeapBuffer raw(raw_size);
  if (raw.data == nullptr) return Status::Error(StatusCode::kResourceExhausted, "PNG: no memory");
  for (int y = 0; y < height; ++y) {
    const uint8_t* cur = pixels + size_t(y) * size_t(stride_bytes);
    const uint8_t* prev = y > 0 ? cur - stride_bytes : nullptr;
    uint8_t* dst = raw.data + size_t(y) * (1 + row_bytes);
    long best_cost = -1;
    for (int filter = 0; filter <= 4; ++filter) {
      long cost = 0;
      for (size_t x = 0; x < row_bytes; ++x) {
        const int a = x >= size_t(channels) ? cur[x - channels] : 0;
        const int b = prev ? prev[x] : 0;
        const int c = prev && x >= size_t(channels) ? prev[x - channels] : 0;
        const int predicted = filter == 0   ? 0
                              : filter == 1 ? a
                              : filter == 2 ? b
                              : filter == 3 ? (a + b) >> 1
                                            : Paeth(a, b, c);
        const int8_t residual = static_cast<int8_t>(cur[x] - predicted);
        cost += std::abs(int{residual});
      }
      if (best_cost < 0 || cost < best_cost) {
        best_cost = cost;
        dst[0] = static_cast<uint8_t>(filter);
      }
    }
    const int filter = dst[0];
    for (size_t x = 0; x < row_bytes; ++x) {
      const int a = x >= size_t(channels) ? cur[x - channels] : 0;
      const int b = prev ? prev[x] : 0;
      const int c = prev && x >= size_t(channels) ? prev[x - channels] : 0;
      const int predicted = filter == 0   ? 0
                            : filter == 1 ? a
                            : filter == 2 ? b
                            : filter == 3 ? (a + b) >> 1
                                          : Paeth(a, b, c);
      dst[1 + x] = static_cast<uint8_t>(cur[x] - predicted);
    }
  }

  std::memcpy(out, kPngSignature, 8);
  size_t pos = 8;
  uint8_t ihdr[13];
  WriteBe32(ihdr, static_cast<uint32_t>(width));
  WriteBe32(ihdr + 4, static_cast<uint32_t>(height));
  ihdr[8] = 8;                         // bits per sample
  ihdr[9] = channels == 1 ? 0 : 2;     // grey or RGB
  ihdr[10] = ihdr[11] = ihdr[12] = 0;  // deflate, adaptive filters, no interlace
  pos += PngChunk(out + pos, "IHDR", ihdr, 13);
  const Result<size_t> z = ZlibDeflate(raw.data, raw_size, out + pos + 8, capacity - pos - 8 - 16);
  if (!z.ok()) return z.status();
  pos += PngChunk(out + pos, "IDAT", out + pos + 8, static_cast<uint32_t>(*z));
  pos += PngChunk(out + pos, "IEND", nullptr, 0);
  return pos;
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
  const size_t bound = EncodedPngBound(width, height, channels);
  HeapBuffer buffer(bound);
  if (buffer.data == nullptr)
    return Status::Error(StatusCode::kResourceExhausted, "PNG: no memory");
  const Result<size_t> size =
      EncodePng(pixels, width, height, stride_bytes, channels, buffer.data, bound);
  if (!size.ok()) return size.status();
  return WriteFile(path, buffer.data, *size);
}
}  // namespace

Status WritePng(const char* path, ConstGrayView image) {
  return WritePngFile(path, image.data, image.width, image.height, image.stride, 1);
}

Status WritePngRgb(const char* path, const uint8_t* rgb, int width, int height, int stride_bytes) {
  return WritePngFile(path, rgb, width, height, stride_bytes, 3);
}

}  // namespace sh::hal
