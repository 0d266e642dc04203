// Small helpers of the commands that report figures: medians, the command line that produced
// them, and writing a text file.
#pragma once

#include <string>
#include <vector>

namespace sh::tools {

float Median(std::vector<float> v);                             // 0 for an empty list
float Max(const std::vector<float>& v);                         // 0 for an empty list
std::string CommandLine(int argc, char** argv);                 // "stereohash " + the arguments
bool WriteTextFile(const char* path, const std::string& text);  // false on any I/O error

}  // namespace sh::tools
