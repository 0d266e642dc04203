// Small helpers of the commands that report figures: medians, the command line that produced
// them, and writing a text file.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

namespace sh::tools {

float Median(std::vector<float> v);                             // 0 for an empty list
float Max(const std::vector<float>& v);                         // 0 for an empty list
std::string CommandLine(int argc, char** argv);                 // "stereohash " + the arguments
bool WriteTextFile(const char* path, const std::string& text);  // false on any I/O error
bool WriteFileBytes(const char* path, const void* data, size_t size);  // false on any I/O error
bool ReadTextFile(const std::string& path, std::string* text);         // false if it cannot be read

}  // namespace sh::tools
