#include "tools/report_util.hpp"

#include <algorithm>
#include <cstdio>

#include "tables/input_file.hpp"

namespace sh::tools {

float Median(std::vector<float> v) {
  if (v.empty()) return 0.0f;
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5f * (v[n / 2 - 1] + v[n / 2]);
}

float Max(const std::vector<float>& v) {
  return v.empty() ? 0.0f : *std::max_element(v.begin(), v.end());
}

std::string CommandLine(int argc, char** argv) {
  std::string s = "stereohash";
  for (int i = 0; i < argc; ++i) s += std::string(" ") + argv[i];
  return s;
}

bool WriteFileBytes(const char* path, const void* data, size_t size) {
  std::FILE* f = std::fopen(path, "wb");
  if (f == nullptr) return false;
  const bool ok = std::fwrite(data, 1, size, f) == size;
  return std::fclose(f) == 0 && ok;
}

bool WriteTextFile(const char* path, const std::string& text) {
  return WriteFileBytes(path, text.data(), text.size());
}

bool ReadTextFile(const std::string& path, std::string* text) {
  // Truth files of recorded sets: a few kilobytes each.
  constexpr size_t kMaxTextFileBytes = size_t{16} << 20;
  return ReadInputFile(path, "file", kMaxTextFileBytes, text).ok();
}

}  // namespace sh::tools
