// `stereohash tables build` inputs: model names kept whole or refused, given once, the folder's
// models.txt deciding which OBJ files are read (printed ones included), numbers read whole.
#include <gtest/gtest.h>

#include <array>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "tests/support/temp_dir.hpp"
#include "tests/support/test_models.hpp"
#include "tests/support/tool_run.hpp"

namespace sh {
namespace {

using testing::TempDir;
using testing::ToolRun;

ToolRun RunTool(const std::string& args) { return testing::RunTool(STEREOHASH_EXE, args); }

void Copy(const std::string& from, const std::string& to) {
  std::filesystem::copy_file(from, to, std::filesystem::copy_options::overwrite_existing);
}

TEST(ModelNamesTool, LongFileStemsAreRefusedNotCut) {
  TempDir dir("names");
  const std::string d = dir.Mkdir("models");
  const std::string stem(40, 'a');
  Copy("models/cube.obj", d + "/" + stem + "1.obj");
  Copy("models/wedge.obj", d + "/" + stem + "2.obj");
  const ToolRun r = RunTool("tables build --models " + d + " --out " + dir.Sub("t.bin"));
  EXPECT_NE(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("the model name (file stem) has 41 characters, at most 31"),
            std::string::npos)
      << r.output;
  EXPECT_FALSE(std::filesystem::exists(dir.Sub("t.bin")));
}

TEST(ModelNamesTool, NamesGivenTwiceAreRefused) {
  TempDir dir("names");
  const ToolRun r =
      RunTool("tables build --models models --names cube,cube --out " + dir.Sub("t.bin"));
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("--names: model 'cube' given twice"), std::string::npos) << r.output;
}

TEST(ModelNamesTool, ModelsTxtGovernsPrintedModelsToo) {
  TempDir dir("names");
  const std::string d = dir.Mkdir("models");
  Copy("models/cube.obj", d + "/cube.obj");
  for (const char* f : {"tea.obj", "tea.mtl", "tea.png"}) {
    Copy(std::string("models/textured/") + f, d + "/" + f);
  }
  std::ofstream(d + "/broken.obj") << "this is no OBJ\n";
  std::ofstream(d + "/models.txt") << "cube\n";
  const ToolRun r = RunTool("tables build --models " + d + " --out " + dir.Sub("t.bin"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const ToolRun info = RunTool("tables info " + dir.Sub("t.bin"));
  ASSERT_EQ(info.exit_code, 0) << info.output;
  EXPECT_NE(info.output.find("cube"), std::string::npos) << info.output;
  EXPECT_EQ(info.output.find("tea"), std::string::npos) << "not listed: " << info.output;
}

// A rendered scene's truth.json names its models as JSON strings: a stem with a quote or a
// backslash must not end the string early, or the truth cannot be read back.
TEST(ModelNamesTool, RenderTruthEscapesModelNames) {
  TempDir dir("names");
  const std::string d = dir.Mkdir("models");
  Copy("models/cube.obj", d + "/cu\"be\\x.obj");
  const ToolRun r = RunTool("render --objects 1 --models " + d + " --out " + dir.Sub("scene"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  std::ifstream in(dir.Sub("scene/truth.json"));
  const std::string truth((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_NE(truth.find("\"model\": \"cu\\\"be\\\\x\""), std::string::npos) << truth;
}

// An ASCII STL of a cube of side 0.5 (in the file's unit) from -0.25 + shift to 0.25 + shift
// on each axis, wound counter-clockwise from outside.
void WriteHalfCubeStl(const std::string& path, double shift = 0) {
  static constexpr int kQuads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4},
                                       {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  std::ofstream out(path);
  out << "solid cube\n";
  for (const auto& q : kQuads) {
    const std::array<int, 3> halves[2] = {{q[0], q[1], q[2]}, {q[0], q[2], q[3]}};
    for (const std::array<int, 3>& tri : halves) {
      out << "facet normal 0 0 0\nouter loop\n";
      for (int k = 0; k < 3; ++k) {
        out << "vertex " << (tri[k] & 1) * 0.5 - 0.25 + shift << " "
            << ((tri[k] >> 1) & 1) * 0.5 - 0.25 + shift << " " << (tri[k] >> 2) * 0.5 - 0.25 + shift
            << "\n";
      }
      out << "endloop\nendfacet\n";
    }
  }
  out << "endsolid cube\n";
}

TEST(ModelNamesTool, CadExportsAreModelsReadInTheirUnit) {
  TempDir dir("names");
  const std::string d = dir.Mkdir("models");
  // `tables build` of the folder with `options`: its exit code, and a line its output must hold.
  auto build = [&](const std::string& options, int exit_code, const char* expected) {
    const ToolRun r =
        RunTool("tables build --models " + d + options + " --out " + dir.Sub("t.bin"));
    EXPECT_EQ(r.exit_code, exit_code) << options << "\n" << r.output;
    EXPECT_NE(r.output.find(expected), std::string::npos) << options << "\n" << r.output;
  };
  WriteHalfCubeStl(d + "/block.stl");
  build("", 1, "block.stl: STL: the model is 0.866 mm across");
  build(" --units ft", 2, "--units takes mm, cm, m or in");
  build(" --sharp-deg 95", 2, "--sharp-deg '95'");
  // 5 mm across: corners too close for any basis of the stereo path.
  build(" --units cm", 0, "warning: model 0 offers no basis within this table's limits");
  build(" --units in", 0,
        "model 0 block       8 corners 12 edges  6 faces, symmetry group of order 24");
  // The set's models as built render a scene to try it on: the part, in millimetres.
  const ToolRun rendered =
      RunTool("render --tables " + dir.Sub("t.bin") + " --objects 1 --out " + dir.Sub("scene"));
  ASSERT_EQ(rendered.exit_code, 0) << rendered.output;
  std::ifstream truth_file(dir.Sub("scene/truth.json"));
  const std::string truth((std::istreambuf_iterator<char>(truth_file)),
                          std::istreambuf_iterator<char>());
  EXPECT_NE(truth.find("\"model\": \"block\""), std::string::npos) << truth;
  // With the file's origin at a corner the rotations about it are only those about the diagonal.
  WriteHalfCubeStl(d + "/block.stl", 0.25);
  build(" --units in", 0,
        "block.stl has a symmetry group of order 24 about its centroid, (6.350, 6.350, 6.350) "
        "mm, but of order 3 about the file's origin");
  build(" --units in --origin centroid", 0,
        "block.stl: model origin at its centroid, (6.350, 6.350, 6.350) mm");
  build(" --units in --origin centroid", 0, "symmetry group of order 24");
}

// What `tables build` of the folder `models` printed and what `tables info` of the set it wrote
// prints.
std::vector<std::string> BuildAndDescribe(const TempDir& dir, const std::string& models) {
  const ToolRun r = RunTool("tables build --models " + models + " --out " + dir.Sub("t.bin"));
  EXPECT_EQ(r.exit_code, 0) << r.output;
  const ToolRun info = RunTool("tables info " + dir.Sub("t.bin"));
  EXPECT_EQ(info.exit_code, 0) << info.output;
  return {r.output, info.output};
}

// A part with a bore through it is built, and `tables build` and `tables info` say which of its
// faces have holes; a part without holes gets no such line.
TEST(ModelNamesTool, FacesWithHolesAreShown) {
  TempDir dir("names");
  const std::string d = dir.Mkdir("models");
  std::ofstream(d + "/plate.obj") << testing::PlateWithHoleObj();
  Copy("models/cube.obj", d + "/cube.obj");
  for (const std::string& out : BuildAndDescribe(dir, d)) {
    EXPECT_NE(
        out.find("model 1 plate      16 corners 24 edges 10 faces, symmetry group of order  8"),
        std::string::npos)
        << out;
    EXPECT_NE(out.find("faces, symmetry group of order  8,   74 bases\n"
                       "    2 faces with holes, 2 holes in all\n"),
              std::string::npos)
        << out;
    EXPECT_EQ(out.find("holes in all"), out.rfind("holes in all")) << out;  // not the cube's
  }
}

// A can exported as STL is a curved side of 32 facets: shown with its area and what is left to
// hash (nothing), and warned of as a part the stereo path cannot find; the cube beside it is not.
TEST(ModelNamesTool, CurvedSurfacesAreShownAndAPartWithNothingToHashIsWarnedOf) {
  TempDir dir("names");
  const std::string d = dir.Mkdir("models");
  testing::WriteAsciiStl(d + "/can.stl", testing::PrismTriangles(32, 20, 30));
  Copy("models/cube.obj", d + "/cube.obj");
  for (const std::string& out : BuildAndDescribe(dir, d)) {
    EXPECT_NE(out.find("model 0 can        64 corners 96 edges 34 faces"), std::string::npos)
        << out;
    EXPECT_NE(out.find("    curved surfaces: 32 facets, 3764 mm2, 32 smooth edges (silhouettes "
                       "only); hashed: 0 of 64 corners, 0 of 96 edges\n"
                       "  warning: model 0 is curved surfaces with fewer than 3 corners to hash"),
              std::string::npos)
        << out;
    EXPECT_EQ(out.find("curved surfaces:"), out.rfind("curved surfaces:")) << out;  // not the cube
    EXPECT_EQ(out.find("warning: model 1"), std::string::npos) << out;
  }
}

TEST(ModelNamesTool, OptionNumbersAreReadWholeAndNamed) {
  TempDir dir("names");
  const std::string out = " --out " + dir.Sub("t.bin");
  ToolRun r = RunTool("tables build --models models --hash-fn 5x" + out);
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("--hash-fn '5x' is not a whole number in 1..5"), std::string::npos)
      << r.output;
  r = RunTool("tables build --models models/colour --spacing-deg abc" + out);
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("--spacing-deg 'abc' is not a number"), std::string::npos) << r.output;
  r = RunTool("tables build --models models --hash-2d similarity --spacing 1" + out);
  EXPECT_NE(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("initial spacing (--spacing, degrees) is 1, outside 2..90"),
            std::string::npos)
      << r.output;
  EXPECT_EQ(r.output.find("aspect table: aspect table"), std::string::npos) << r.output;
  // A misspelt last option is not only "missing its value".
  r = RunTool("recognize --frobnicate");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("--frobnicate is not an option, or needs a value"), std::string::npos)
      << r.output;
}

}  // namespace
}  // namespace sh
