// Binary 8-bit PGM (P5) reading for recorded stereo frames, straight into caller-owned buffers.
//
// Uses POSIX open/read so that playback does not touch the heap once started.
#pragma once

#include <cstddef>
#include <cstdint>

#include "recog/base/status.hpp"
#include "recog/image/image.hpp"

namespace sh::hal {

struct PgmHeader {
  int width = 0;
  int height = 0;
  int max_value = 0;
  size_t data_offset = 0;  // bytes from the start of the file to the first pixel
};

// Largest header accepted (magic, size, maxval and comments).
inline constexpr size_t kMaxPgmHeaderBytes = 1024;

// Parses a P5 header from the first `size` bytes of a file. Errors: kInvalidArgument (not a PGM,
// bad numbers), kUnimplemented (P2 ASCII or 16-bit PGM), kOutOfRange (larger than
// kMaxImageWidth x kMaxImageHeight), kDataLoss (file ends inside the header).
Status ParsePgmHeader(const uint8_t* data, size_t size, PgmHeader* out);

// Reads the header of the file at `path`; errors name the file by its base name.
Status ReadPgmHeader(const char* path, PgmHeader* out);

// Reads the pixels of the P5 file at `path` into `dst`, which must have exactly the file's size
// (kInvalidArgument otherwise). A file shorter than its header promises is kDataLoss. Pixel values
// are copied as stored: a maxval below 255 is not rescaled.
Status ReadPgmInto(const char* path, GrayView dst);

// The part of `path` after the last '/', for short error messages.
const char* PathBaseName(const char* path);

}  // namespace sh::hal
