#include <cstdint>

#include "tables/aspect_file.hpp"

extern "C" const uint8_t stereohash_default_aspect_blob[];
extern "C" const uint8_t stereohash_default_aspect_blob_end[];

namespace sh {

const void* DefaultAspectBlob() { return stereohash_default_aspect_blob; }
size_t DefaultAspectBlobSize() {
  return size_t(stereohash_default_aspect_blob_end - stereohash_default_aspect_blob);
}

Result<AspectTableView> OpenDefaultAspectTable() {
  return AspectTableView::Open(DefaultAspectBlob(), DefaultAspectBlobSize());
}

}  // namespace sh
