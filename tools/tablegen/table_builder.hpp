// Offline preprocessing of geometric hashing: every valid basis of every model, the other model
// features expressed in it, binned into the two hash arrays, serialised as a table blob.
//
// Runs on the host (the `stereohash tables build` command and the build step that bakes the
// default tables into the firmware); it allocates freely and is never on the per-frame path.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "recog/base/status.hpp"
#include "recog/hashing/basis.hpp"
#include "recog/model/model.hpp"

namespace sh {

struct TableBuildOptions {
  HashFunction hash_function = HashFunction::kLinePointMidway;
  BasisLimits limits;
  float point_bin_mm = 5.0f;  // thesis table 5.3
  float line_bin_mm = 10.0f;
};

struct ModelBasisCount {
  std::string model;
  uint32_t bases = 0;  // stored model bases (frames), one per class of symmetric bases
  uint32_t point_entries = 0;
  uint32_t line_entries = 0;
};

struct TableBuildReport {
  std::vector<ModelBasisCount> per_model;
  uint32_t bases = 0;
  uint32_t point_entries = 0;
  uint32_t line_entries = 0;
  uint32_t max_point_bin_entries = 0;
  uint32_t max_line_bin_entries = 0;
};

// Builds the blob. Models get their symmetry group filled in (Model::symmetries) on the way.
Result<std::vector<uint8_t>> BuildTableBlob(std::vector<Model> models,
                                            const TableBuildOptions& options,
                                            TableBuildReport* report = nullptr);

}  // namespace sh
