// The aspect tables of the monocular mode in `stereohash tables build|info` (thesis ch. 6).
#pragma once

#include <string>

namespace sh::tools {

// `tables build --hash-2d similarity|affine ...`: argv as for RunBuild. Returns the exit code.
int BuildAspectTable(int argc, char** argv);

// The 2-D tables of the reference models beside the thesis's (tables 6.1, 6.2).
int CompareAspectsWithThesis(const std::string& models_dir);

// Describes `path` if it is an aspect table file ("builtin-aspects": the linked-in one); false
// (nothing printed) if it is not one.
bool DescribeAspectFile(const std::string& path, int* exit_code);

}  // namespace sh::tools
