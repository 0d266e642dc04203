// `stereohash tables build|info` for printed (textured) models: a model folder's printed OBJs
// become a feature database (docs/texture.md); `info` describes one.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "recog/base/status.hpp"
#include "tables/feature_db_view.hpp"

namespace sh::tools {

// The *.obj files of `dir`, sorted, split into printed models (a face with a texture image)
// and plain ones. Errors name the file that does not load.
Status ClassifyModelFolder(const std::string& dir, std::vector<std::string>* printed,
                           std::vector<std::string>* plain);

// Learns the feature database of the printed models `paths` (the TEXTURE_FEATURES section);
// prints what it holds.
Result<std::vector<uint8_t>> BuildPrintedSection(const std::vector<std::string>& paths);

// Prints what a feature database holds.
void DescribeFeatureDb(const FeatureDbView& db, size_t size);

}  // namespace sh::tools
