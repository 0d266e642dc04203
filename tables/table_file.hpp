// A table blob file mapped read-only into memory and validated in place.
#pragma once

#include <cstddef>

#include "recog/base/status.hpp"
#include "tables/table_view.hpp"

namespace sh {

// A file mapped read-only (page-aligned, so any blob in it is 8-byte aligned). `what` names the
// kind of file in messages ("table file").
class MappedFile {
 public:
  MappedFile() = default;
  ~MappedFile();
  MappedFile(const MappedFile&) = delete;
  MappedFile& operator=(const MappedFile&) = delete;

  Status Open(const char* path, const char* what);
  void Close();
  const void* data() const { return data_; }
  size_t size() const { return size_; }

 private:
  void* data_ = nullptr;
  size_t size_ = 0;
};

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
  size_t size() const { return file_.size(); }

 private:
  MappedFile file_;
  TableView view_;
};

// The reference models' hash fn 5 tables, built at compile time and linked in as read-only data.
const void* DefaultTableBlob();
size_t DefaultTableBlobSize();
Result<TableView> OpenDefaultTable();

}  // namespace sh
