// A table blob file mapped read-only into memory and validated in place.
#pragma once

#include <cstddef>

#include "recog/base/status.hpp"
#include "tables/table_view.hpp"

namespace sh {

class MappedTable {
 public:
  MappedTable() = default;
  ~MappedTable();
  MappedTable(const MappedTable&) = delete;
  MappedTable& operator=(const MappedTable&) = delete;

  // Maps `path` and validates it; on failure nothing stays mapped.
  Status Open(const char* path);
  void Close();
  const TableView& view() const { return view_; }
  size_t size() const { return size_; }

 private:
  void* data_ = nullptr;
  size_t size_ = 0;
  TableView view_;
};

// The reference models' hash fn 5 tables, built at compile time and linked in as read-only data.
const void* DefaultTableBlob();
size_t DefaultTableBlobSize();
Result<TableView> OpenDefaultTable();

}  // namespace sh
