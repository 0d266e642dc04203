#include "tables/shape_views_file.hpp"

namespace sh {

void MappedShapeViews::Close() {
  file_.Close();
  view_ = ShapeViewsView();
}

Status MappedShapeViews::Open(const char* path) {
  Close();
  SH_RETURN_IF_ERROR(file_.Open(path, "view database"));
  Result<ShapeViewsView> view = ShapeViewsView::Open(file_.data(), file_.size());
  if (!view.ok()) {
    file_.Close();
    return view.status().WithContext("%s", path);
  }
  view_ = *view;
  return Status::Ok();
}

}  // namespace sh
