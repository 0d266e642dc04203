// Reading and writing the small files tests boot from or copy (models, sets, configurations).
#pragma once

#include <cstddef>
#include <cstdio>
#include <string>

namespace sh::testing {

// The whole file, or "" when it cannot be read.
inline std::string ReadTestFile(const std::string& path) {
  std::string text;
  std::FILE* f = std::fopen(path.c_str(), "rb");
  if (f == nullptr) return text;
  char buffer[4096];
  size_t n;
  while ((n = std::fread(buffer, 1, sizeof(buffer), f)) > 0) text.append(buffer, n);
  std::fclose(f);
  return text;
}

inline bool WriteTestFile(const std::string& path, const void* data, size_t size) {
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (f == nullptr) return false;
  const bool ok = std::fwrite(data, 1, size, f) == size;
  return std::fclose(f) == 0 && ok;
}

}  // namespace sh::testing
