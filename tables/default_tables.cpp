#include <cstdint>

#include "tables/table_file.hpp"

extern "C" const uint8_t stereohash_default_table_blob[];
extern "C" const uint8_t stereohash_default_table_blob_end[];

namespace sh {

const void* DefaultTableBlob() { return stereohash_default_table_blob; }
size_t DefaultTableBlobSize() {
  return size_t(stereohash_default_table_blob_end - stereohash_default_table_blob);
}

Result<TableView> OpenDefaultTable() {
  return TableView::Open(DefaultTableBlob(), DefaultTableBlobSize());
}

}  // namespace sh
