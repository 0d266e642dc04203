// Read-only, validated, zero-copy access to a view database blob (shape_views_format.hpp). The
// search over it (projection into PCA space, nearest views) is the shape path's:
// recog/shape/view_database.hpp.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>

#include "recog/base/status.hpp"
#include "recog/model/model.hpp"
#include "tables/shape_views_format.hpp"

namespace sh {

class ShapeViewsView {
 public:
  ShapeViewsView() = default;
  // Validates everything a corrupt, truncated or foreign blob could get wrong; errors name the
  // problem. The memory must outlive the view and be at least 8-byte aligned.
  static Result<ShapeViewsView> Open(const void* blob, size_t size);

  bool empty() const { return header_ == nullptr; }
  const ShapeViewsHeader& header() const { return *header_; }
  uint32_t model_count() const { return header_ ? header_->n_models : 0; }
  const Model& model(uint32_t i) const { return models_[i]; }
  const ShapeModelRecord& shape_model(uint32_t i) const { return shape_models_[i]; }
  uint32_t view_count() const { return header_->n_views; }
  const ShapeViewRecord& view(uint32_t i) const { return views_[i]; }
  const QCoefficient::Raw* coefficients(uint32_t view) const {
    return coefficients_ + static_cast<size_t>(view) * header_->component_stride;
  }
  int FindModel(const char* name) const;

  // Orientation of view i (ray_R_model).
  Eigen::Matrix3f ViewRotation(uint32_t i) const;
  // The PCA mean window (kShapeViewWindowPixels) and basis (n_components rows of
  // kShapeViewWindowPixels Q2.14 entries).
  const float* mean() const { return mean_; }
  const QBasis::Raw* basis() const { return basis_; }

 private:
  const ShapeViewsHeader* header_ = nullptr;
  const Model* models_ = nullptr;
  const ShapeModelRecord* shape_models_ = nullptr;
  const float* mean_ = nullptr;
  const QBasis::Raw* basis_ = nullptr;
  const ShapeViewRecord* views_ = nullptr;
  const QCoefficient::Raw* coefficients_ = nullptr;
};

}  // namespace sh
