// The host programs: `stereohash` loads no OpenCV, and runs the commands built with OpenCV from
// stereohash-cv beside it (tools/cv_program.hpp), naming that program when it is missing.
#include <gtest/gtest.h>
#include <stdlib.h>

#include <cctype>
#include <cstdlib>
#include <string>

#include "tests/support/temp_dir.hpp"
#include "tests/support/tool_run.hpp"

namespace sh {
namespace {

using testing::RunTool;
using testing::ToolRun;

std::string Lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

TEST(Programs, StereohashLoadsNoOpenCv) {
  const ToolRun r = RunTool("ldd", STEREOHASH_EXE);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("libc.so"), std::string::npos) << r.output;
  EXPECT_EQ(Lower(r.output).find("opencv"), std::string::npos) << r.output;
}

TEST(Programs, OpenCvCommandsAreListed) {
  const ToolRun r = RunTool(STEREOHASH_EXE, "--help");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  for (const char* name : {"calibrate ", "calibrate-table ", "calibrate-handeye ", "recognize "}) {
    EXPECT_NE(r.output.find(name), std::string::npos) << name << "\n" << r.output;
  }
}

#ifdef STEREOHASH_CV_BUILT
TEST(Programs, OpenCvCommandsRunThroughStereohash) {
  const ToolRun r = RunTool(STEREOHASH_EXE, "calibrate-table --help");
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("usage: stereohash calibrate-table"), std::string::npos) << r.output;
  const ToolRun bad = RunTool(STEREOHASH_EXE, "calibrate --board 3");
  EXPECT_EQ(bad.exit_code, 2) << bad.output;
  EXPECT_NE(bad.output.find("--board wants"), std::string::npos) << bad.output;
}
#endif

// A `stereohash` copied without its sibling: the recognition commands work, the OpenCV ones say
// which program is missing and where it was looked for.
TEST(Programs, MissingCvProgramIsNamed) {
  const testing::TempDir temp("programs");
  ASSERT_TRUE(temp.ok());
  const std::string& dir = temp.path();
  const std::string copy = dir + "/stereohash";
  ASSERT_EQ(RunTool("cp", std::string(STEREOHASH_EXE) + " " + copy).exit_code, 0);
  const ToolRun help = RunTool(copy, "recognize --help");
  EXPECT_EQ(help.exit_code, 0) << help.output;
  const ToolRun r = RunTool(copy, "calibrate-handeye --help");
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find("stereohash-cv"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find(dir + "/stereohash-cv"), std::string::npos) << r.output;
}

}  // namespace
}  // namespace sh
