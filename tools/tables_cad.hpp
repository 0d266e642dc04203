// `tables build` and CAD exports (tools/tablegen/cad_import.hpp): the options that govern how they
// are read, and reading a folder's models with them.
#pragma once

#include <string>
#include <vector>

#include "recog/base/status.hpp"
#include "recog/model/model.hpp"
#include "tools/tablegen/cad_import.hpp"

namespace sh::tools {

// One CAD option of `tables build` at argv[*i] (advancing *i past its value): --units,
// --sharp-deg, --origin. 1 taken, 0 not a CAD option, -1 a bad value (message printed).
int ParseCadOption(int argc, char** argv, int* i, CadImportOptions* options);

// The help lines of those options.
extern const char* const kCadOptionsHelp;

// The models `names` of `dir` in that order, OBJ and CAD exports alike; prints where each CAD
// export's model origin lies in its file's frame.
Status LoadFolderModels(const std::string& dir, const std::vector<std::string>& names,
                        const CadImportOptions& options, std::vector<Model>* models);

}  // namespace sh::tools
