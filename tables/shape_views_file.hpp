// A view database file (recog/shape/view_database.hpp) mapped read-only and validated in place.
#pragma once

#include <cstddef>

#include "recog/base/status.hpp"
#include "recog/shape/view_database.hpp"
#include "tables/table_file.hpp"

namespace sh {

class MappedShapeViews {
 public:
  // Maps `path` and validates it; on failure nothing stays mapped.
  Status Open(const char* path);
  void Close();
  const ShapeViewsView& view() const { return view_; }
  size_t size() const { return file_.size(); }

 private:
  MappedFile file_;
  ShapeViewsView view_;
};

}  // namespace sh
