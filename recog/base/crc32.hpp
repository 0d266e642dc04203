// CRC-32 (IEEE 802.3 / zlib / PNG polynomial 0xEDB88320, reflected, init and final xor
// 0xFFFFFFFF). Used by the table blob header and the PNG writer.
#pragma once

#include <cstddef>
#include <cstdint>

namespace sh {

// Continues a CRC over more data: Crc32(b, nb, Crc32(a, na)) == Crc32(a ++ b).
uint32_t Crc32(const void* data, size_t length, uint32_t crc = 0);

// The CRC-32 of a blob that holds its own CRC at `crc_offset` (4 bytes in its header): every
// byte of [0, size) with that field read as zero, so that no header bit escapes the check.
uint32_t BlobCrc32(const void* blob, size_t size, size_t crc_offset);

}  // namespace sh
