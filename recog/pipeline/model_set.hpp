// One model set over the recognition paths' data: the hash tables' models (polyhedra) first,
// then the view database's models (colour parts). A model's id, the index reported in JSON and
// over CAN, is its position in this order.
#pragma once

#include <cstdint>
#include <cstring>

#include "recog/model/model.hpp"
#include "recog/shape/view_database.hpp"
#include "tables/table_view.hpp"

namespace sh {

class ModelSet {
 public:
  ModelSet() = default;
  // Either may be null or empty.
  ModelSet(const TableView* hash, const ShapeViewsView* shape)
      : hash_(hash != nullptr && hash->model_count() > 0 ? hash : nullptr),
        shape_(shape != nullptr && !shape->empty() ? shape : nullptr) {}

  uint32_t hash_count() const { return hash_ ? hash_->model_count() : 0; }
  uint32_t shape_count() const { return shape_ ? shape_->model_count() : 0; }
  uint32_t count() const { return hash_count() + shape_count(); }
  // Id of the first colour part (the shape path's model 0).
  uint32_t shape_offset() const { return hash_count(); }
  bool is_shape(uint32_t id) const { return id >= hash_count() && id < count(); }

  const Model& model(uint32_t id) const {
    return id < hash_count() ? hash_->model(id) : shape_->model(id - hash_count());
  }
  // Id of the model called `name`, or -1.
  int Find(const char* name) const {
    for (uint32_t i = 0; i < count(); ++i) {
      if (std::strncmp(model(i).name, name, kMaxModelNameLength + 1) == 0) return int(i);
    }
    return -1;
  }

 private:
  const TableView* hash_ = nullptr;
  const ShapeViewsView* shape_ = nullptr;
};

}  // namespace sh
