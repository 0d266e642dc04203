// How `stereohash` runs the commands built with OpenCV: stereohash-cv from the running program's
// own directory, with the same command line (tools/cv_commands.hpp).
#pragma once

#include "tools/cv_commands.hpp"

namespace sh::tools {

// Whether stereohash-cv is an executable file next to the running program.
bool CvProgramPresent();

// Replaces this process by stereohash-cv with the same arguments (argv[0] is the command name, as
// Command::run receives it). Returns only when that fails: prints a message naming the program
// and the path it was looked for at, and returns exit code 1.
int RunInCvProgram(int argc, char** argv);

}  // namespace sh::tools
