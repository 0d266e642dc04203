// One model set over the recognition paths' data: the hash tables' models (polyhedra) first,
// then the view database's models (colour parts), then the feature database's models (printed
// cartons). A model's id, the index reported in JSON and over CAN, is its position in this
// order.
#pragma once

#include <cstdint>
#include <cstring>

#include "recog/model/model.hpp"
#include "recog/shape/view_database.hpp"
#include "tables/feature_db_view.hpp"
#include "tables/table_view.hpp"

namespace sh {

class ModelSet {
 public:
  ModelSet() = default;
  // Any may be null or empty.
  ModelSet(const TableView* hash, const ShapeViewsView* shape,
           const FeatureDbView* printed = nullptr)
      : hash_(hash != nullptr && hash->model_count() > 0 ? hash : nullptr),
        shape_(shape != nullptr && !shape->empty() ? shape : nullptr),
        printed_(printed != nullptr && !printed->empty() && printed->model_count() > 0 ? printed
                                                                                       : nullptr) {}

  uint32_t hash_count() const { return hash_ ? hash_->model_count() : 0; }
  uint32_t shape_count() const { return shape_ ? shape_->model_count() : 0; }
  uint32_t printed_count() const { return printed_ ? printed_->model_count() : 0; }
  uint32_t count() const { return hash_count() + shape_count() + printed_count(); }
  // Id of the first colour part (the shape path's model 0).
  uint32_t shape_offset() const { return hash_count(); }
  bool is_shape(uint32_t id) const { return id >= hash_count() && id < printed_offset(); }
  // Id of the first printed model (the feature database's model 0).
  uint32_t printed_offset() const { return hash_count() + shape_count(); }
  bool is_printed(uint32_t id) const { return id >= printed_offset() && id < count(); }

  // The data of each path, or null when the set has none of its models.
  const TableView* hash() const { return hash_; }
  const ShapeViewsView* shape() const { return shape_; }
  const FeatureDbView* printed() const { return printed_; }

  const Model& model(uint32_t id) const {
    if (id < hash_count()) return hash_->model(id);
    if (id < printed_offset()) return shape_->model(id - hash_count());
    return printed_->model(id - printed_offset());
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
  const FeatureDbView* printed_ = nullptr;
};

}  // namespace sh
