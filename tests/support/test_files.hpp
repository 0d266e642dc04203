// Writing the small files tests boot from or copy (models, sets, configurations); reading them:
// ReadFileText (tool_run.hpp).
#pragma once

#include <cstddef>
#include <cstdio>
#include <string>

namespace sh::testing {

inline bool WriteTestFile(const std::string& path, const void* data, size_t size) {
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (f == nullptr) return false;
  const bool ok = std::fwrite(data, 1, size, f) == size;
  return std::fclose(f) == 0 && ok;
}

}  // namespace sh::testing
