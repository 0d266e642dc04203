// Test helper: runs the `stereohash` program (or any command) through the shell and collects
// its exit code and output, for the end-to-end tests of the host tools.
#pragma once

#include <sys/wait.h>

#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>

namespace sh::testing {

struct ToolRun {
  int exit_code = -1;
  bool signalled = false;
  std::string output;  // stdout and stderr
};

// `program args 2>&1`.
inline ToolRun RunTool(const std::string& program, const std::string& args) {
  ToolRun r;
  const std::string command = program + " " + args + " 2>&1";
  FILE* pipe = popen(command.c_str(), "r");
  if (pipe == nullptr) return r;
  char buffer[4096];
  size_t n;
  while ((n = fread(buffer, 1, sizeof(buffer), pipe)) > 0) r.output.append(buffer, n);
  const int status = pclose(pipe);
  r.signalled = WIFSIGNALED(status);
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return r;
}

// The whole file, or "" if it cannot be read.
inline std::string ReadFileText(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

}  // namespace sh::testing
