// zlib (RFC 1950) stream decoder with DEFLATE (RFC 1951) stored, fixed- and dynamic-Huffman
// blocks. Input arrives in pieces (PNG splits its stream over IDAT chunks) and output leaves
// through a sink, so the decoder needs no buffer larger than the 32 KiB DEFLATE window.
#pragma once

#include <cstddef>
#include <cstdint>

#include "recog/base/status.hpp"

namespace sh::hal {

// Supplies the compressed stream piece by piece.
class ByteSource {
 public:
  // Points *data at the next piece and returns its size; returns 0 at the end of the input.
  virtual size_t Next(const uint8_t** data) = 0;

 protected:
  ~ByteSource() = default;
};

// Receives the decompressed bytes in order. A non-ok Status stops decoding and is returned.
class ByteSink {
 public:
  virtual Status Write(const uint8_t* data, size_t size) = 0;

 protected:
  ~ByteSink() = default;
};

// Adler-32 as used by the zlib trailer. Continue a running checksum by passing it as `adler`.
uint32_t Adler32(const uint8_t* data, size_t size, uint32_t adler = 1);

// Decodes one complete zlib stream, verifying its header and Adler-32 trailer. Errors:
// kDataLoss for a truncated stream or checksum mismatch, kInvalidArgument for malformed data.
Status ZlibInflate(ByteSource& source, ByteSink& sink);

}  // namespace sh::hal
