#include "tables/aspect_file.hpp"

namespace sh {

void MappedAspectTable::Close() {
  file_.Close();
  view_ = AspectTableView();
}

Status MappedAspectTable::Open(const char* path) {
  Close();
  SH_RETURN_IF_ERROR(file_.Open(path, "aspect table"));
  Result<AspectTableView> view = AspectTableView::Open(file_.data(), file_.size());
  if (!view.ok()) {
    file_.Close();
    return view.status().WithContext("%s", path);
  }
  view_ = *view;
  return Status::Ok();
}

}  // namespace sh
