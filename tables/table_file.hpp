// A table blob file mapped read-only into memory and validated in place.
#pragma once

#include <cstddef>

#include "recog/base/status.hpp"
#include "tables/model_set.hpp"
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

// A blob file mapped read-only and validated in place by `View::Open(data, size)` (hash tables,
// aspect tables, view databases, feature databases): a bare blob of that kind, or the `kind`
// section of a model set (tables/model_set.hpp; the container is validated first). `what` names
// the kind of file in messages.
template <typename View>
class MappedView {
 public:
  MappedView(const char* what, SectionKind kind) : what_(what), kind_(kind) {}

  // Maps `path` and validates it; on failure nothing stays mapped.
  Status Open(const char* path) {
    Close();
    SH_RETURN_IF_ERROR(file_.Open(path, what_));
    Result<BlobSpan> blob = SectionOrBareBlob(file_.data(), file_.size(), kind_);
    Result<View> view =
        blob.ok() ? View::Open(blob->data, blob->size) : Result<View>(blob.status());
    if (!view.ok()) {
      file_.Close();
      return view.status().WithContext("%s", path);
    }
    blob_ = *blob;
    view_ = *view;
    return Status::Ok();
  }
  void Close() {
    file_.Close();
    blob_ = BlobSpan();
    view_ = View();
  }
  const View& view() const { return view_; }
  // The blob the view reads: the whole file, or its section of a model set.
  const void* blob() const { return blob_.data; }
  size_t size() const { return blob_.size; }
  // The identity of the whole file (its model set's or bare blob's header CRC-32), 0 when none
  // is open.
  uint32_t file_crc32() const { return BlobHeaderCrc32(file_.data(), file_.size()); }

 private:
  const char* what_;
  SectionKind kind_;
  MappedFile file_;
  BlobSpan blob_;
  View view_;
};

// The kinds a file holds (BlobKinds: a model set's sections, or the one kind of a bare blob);
// errors name the file.
Result<uint32_t> FileBlobKinds(const char* path);

// The identity of the blob in a file (BlobHeaderCrc32 of the model set or bare blob it holds);
// errors name the file (missing, special, empty, shorter than a header).
Result<uint32_t> FileBlobCrc32(const char* path);

class MappedTable : public MappedView<TableView> {
 public:
  MappedTable() : MappedView("table file", SectionKind::kHash3d) {}
};

// The reference models' hash fn 5 tables, built at compile time and linked in as read-only data.
const void* DefaultTableBlob();
size_t DefaultTableBlobSize();
Result<TableView> OpenDefaultTable();

}  // namespace sh
