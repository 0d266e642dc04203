// The aspect tables of the monocular mode in `stereohash tables build|info` (thesis ch. 6).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "recog/base/status.hpp"
#include "recog/model/model.hpp"
#include "tables/aspect_view.hpp"
#include "tools/tablegen/aspect_builder.hpp"

namespace sh::tools {

// `tables build` options of the aspect table, for its --help.
extern const char kAspectOptionsHelp[];

// One aspect option of `tables build` at argv[*i] (advancing *i past its value): 1 taken, 0 not
// an aspect option, -1 a bad value (message printed). `--hash-2d` sets *wanted.
int ParseAspectOption(int argc, char** argv, int* i, AspectBuildOptions* options, bool* wanted);

// The aspect table of `models` (the ASPECTS_2D section); prints what it holds.
Result<std::vector<uint8_t>> BuildAspectSection(const std::vector<Model>& models,
                                                const AspectBuildOptions& options);

// Prints what an aspect table holds.
void DescribeAspects(const AspectTableView& view, size_t size);

// The 2-D tables of the reference models beside the thesis's (tables 6.1, 6.2).
int CompareAspectsWithThesis(const std::string& models_dir);

}  // namespace sh::tools
