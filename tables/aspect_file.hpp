// Aspect tables on disk (mapped and validated in place) and the reference models' aspect table
// linked into the binaries.
#pragma once

#include <cstddef>

#include "recog/base/status.hpp"
#include "tables/aspect_view.hpp"
#include "tables/table_file.hpp"

namespace sh {

class MappedAspectTable : public MappedView<AspectTableView> {
 public:
  MappedAspectTable() : MappedView("aspect table", SectionKind::kAspects2d) {}
};

// The six reference models' similarity aspect table, built when the project builds
// (stereohash_aspectgen, default AspectBuildOptions) and linked in as read-only data.
const void* DefaultAspectBlob();
size_t DefaultAspectBlobSize();
Result<AspectTableView> OpenDefaultAspectTable();

}  // namespace sh
