#include "tools/cv_program.hpp"

#include <unistd.h>

#include <cerrno>
#include <climits>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include "tools/command.hpp"

namespace sh::tools {
namespace {

// The path stereohash-cv would have: the running program's directory (from /proc/self/exe, so it
// does not depend on PATH or on how `stereohash` was started) plus kCvProgramName. Empty when the
// running program's path cannot be read.
std::string CvProgramPath() {
  char self[PATH_MAX];
  const ssize_t n = readlink("/proc/self/exe", self, sizeof(self) - 1);
  if (n <= 0) return std::string();
  self[n] = '\0';
  std::string dir(self);
  const std::size_t slash = dir.rfind('/');
  dir.resize(slash == std::string::npos ? 0 : slash + 1);
  return dir + kCvProgramName;
}

int RunCalibrateInCvProgram(int argc, char** argv) { return RunInCvProgram(argc, argv); }

}  // namespace

bool CvProgramPresent() {
  const std::string path = CvProgramPath();
  return !path.empty() && access(path.c_str(), X_OK) == 0;
}

int RunInCvProgram(int argc, char** argv) {
  const std::string path = CvProgramPath();
  if (path.empty()) {
    std::fprintf(stderr, "stereohash %s: cannot find the running program's directory (%s)\n",
                 argv[0], std::strerror(errno));
    return 1;
  }
  std::vector<char*> args;
  args.reserve(static_cast<std::size_t>(argc) + 2);
  args.push_back(const_cast<char*>(path.c_str()));
  for (int i = 0; i < argc; ++i) args.push_back(argv[i]);
  args.push_back(nullptr);
  execv(path.c_str(), args.data());
  const int err = errno;
  std::fprintf(stderr,
               "stereohash %s: this command is in the program %s, which could not be run from %s "
               "(%s); it is built beside stereohash when OpenCV is installed (README.md)\n",
               argv[0], kCvProgramName, path.c_str(), std::strerror(err));
  return 1;
}

// The commands themselves are registered in stereohash-cv; here they only run it.
SH_REGISTER_COMMAND(calibrate, kCalibrateSummary, RunCalibrateInCvProgram);
static const CommandRegistrar kCalibrateTableCommand({"calibrate-table", kCalibrateTableSummary,
                                                      RunCalibrateInCvProgram});
static const CommandRegistrar kCalibrateHandEyeCommand({"calibrate-handeye",
                                                        kCalibrateHandEyeSummary,
                                                        RunCalibrateInCvProgram});

}  // namespace sh::tools
