// Test helper: a 64-byte aligned copy of a blob, as mmap and linked-in data provide.
#pragma once

#include <cstdint>
#include <cstring>
#include <vector>

namespace sh::testing {

struct AlignedBlob {
  explicit AlignedBlob(const std::vector<uint8_t>& bytes) : size(bytes.size()) {
    storage.resize(bytes.size() + 64);
    data = storage.data() + (64 - reinterpret_cast<uintptr_t>(storage.data()) % 64) % 64;
    std::memcpy(data, bytes.data(), bytes.size());
  }
  std::vector<uint8_t> storage;
  uint8_t* data;
  size_t size;
};

}  // namespace sh::testing
