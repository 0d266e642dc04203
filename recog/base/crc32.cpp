#include "recog/base/crc32.hpp"

#include <array>

namespace sh {
namespace {

constexpr std::array<uint32_t, 256> MakeTable() {
  std::array<uint32_t, 256> table{};
  for (uint32_t i = 0; i < 256; ++i) {
    uint32_t c = i;
    for (int k = 0; k < 8; ++k) c = (c & 1u) ? 0xEDB88320u ^ (c >> 1) : c >> 1;
    table[i] = c;
  }
  return table;
}

constexpr std::array<uint32_t, 256> kTable = MakeTable();

}  // namespace

uint32_t Crc32(const void* data, size_t length, uint32_t crc) {
  const auto* bytes = static_cast<const uint8_t*>(data);
  crc = ~crc;
  for (size_t i = 0; i < length; ++i) crc = kTable[(crc ^ bytes[i]) & 0xffu] ^ (crc >> 8);
  return ~crc;
}

uint32_t BlobCrc32(const void* blob, size_t size, size_t crc_offset) {
  const auto* bytes = static_cast<const uint8_t*>(blob);
  const uint8_t zero[4] = {};
  uint32_t crc = Crc32(bytes, crc_offset);
  crc = Crc32(zero, sizeof(zero), crc);
  return Crc32(bytes + crc_offset + sizeof(zero), size - crc_offset - sizeof(zero), crc);
}

}  // namespace sh
