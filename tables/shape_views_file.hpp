// A view database file (tables/shape_views_view.hpp) mapped read-only and validated in place.
#pragma once

#include <cstddef>

#include "recog/base/status.hpp"
#include "tables/shape_views_view.hpp"
#include "tables/table_file.hpp"

namespace sh {

class MappedShapeViews : public MappedView<ShapeViewsView> {
 public:
  MappedShapeViews() : MappedView("view database", SectionKind::kShapeViews) {}
};

}  // namespace sh
