// CRC-32 (IEEE 802.3 / zlib / PNG polynomial 0xEDB88320, reflected, init and final xor
// 0xFFFFFFFF). Used by PNG chunks and the table blob format to detect corrupted data.
#pragma once

#include <cstddef>
#include <cstdint>

namespace sh {

// CRC-32 of `size` bytes. To checksum data in pieces, pass the previous result as `crc`:
// Crc32(b, nb, Crc32(a, na)) == Crc32(a followed by b).
uint32_t Crc32(const void* data, size_t size, uint32_t crc = 0);

}  // namespace sh
