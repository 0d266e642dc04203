// zlib (RFC 1950) stream encoder: greedy LZ77 with fixed-Huffman DEFLATE blocks, falling back to
// stored blocks when those would be smaller (noisy images). Enough for simulator output files.
#pragma once

#include <cstddef>
#include <cstdint>

#include "recog/base/status.hpp"

namespace sh::hal {

// Output capacity that ZlibDeflate always fits into for `size` input bytes.
size_t ZlibDeflateBound(size_t size);

// Compresses in[0..size) into out[0..capacity) and returns the stream length. Fails with
// kResourceExhausted when capacity < ZlibDeflateBound(size) and the stream does not fit.
Result<size_t> ZlibDeflate(const uint8_t* in, size_t size, uint8_t* out, size_t capacity);

}  // namespace sh::hal
