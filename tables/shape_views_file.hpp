// A view database file (recog/shape/view_database.hpp) mapped read-only and validated in place.
#pragma once

#include <cstddef>

#include "recog/base/status.hpp"
#include "recog/shape/view_database.hpp"
#include "tables/table_file.hpp"

namespace sh {

class MappedShapeViews : public MappedView<ShapeViewsView> {
 public:
  MappedShapeViews() : MappedView("view database", SectionKind::kShapeViews) {}
};

}  // namespace sh
