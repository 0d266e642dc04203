// Read-only, validated, zero-copy access to an aspect table (aspect_format.hpp).
//
// Open() checks everything a corrupt, truncated or foreign blob could get wrong before any
// pointer into it is handed out; afterwards accessors are plain pointer arithmetic. The memory
// must outlive the view and be at least 8-byte aligned.
#pragma once

#include <cstddef>
#include <cstdint>

#include "recog/base/status.hpp"
#include "tables/aspect_format.hpp"
#include "tables/table_view.hpp"

namespace sh {

class AspectTableView {
 public:
  AspectTableView() = default;
  static Result<AspectTableView> Open(const void* blob, size_t size);

  bool valid() const { return header_ != nullptr; }
  const AspectHeader& header() const { return *header_; }
  AspectBasisKind basis_kind() const { return static_cast<AspectBasisKind>(header_->basis_kind); }

  uint32_t model_count() const { return header_->n_models; }
  const Model& model(uint32_t i) const { return models_[i]; }
  int FindModel(const char* name) const;

  uint32_t aspect_count() const { return header_->n_aspects; }
  const AspectRecord& aspect(uint32_t i) const { return aspects_[i]; }
  uint32_t basis_count() const { return header_->n_bases; }
  const AspectBasis& basis(uint32_t i) const { return bases_[i]; }

  const Grid2d& point_grid() const { return header_->point_grid; }
  const Grid2d& line_grid() const { return header_->line_grid; }
  uint32_t point_entry_count() const { return header_->n_point_entries; }
  uint32_t line_entry_count() const { return header_->n_line_entries; }
  const AspectPointEntry* point_entries() const { return point_entries_; }
  const AspectLineEntry* line_entries() const { return line_entries_; }
  const uint32_t* point_bin_offsets() const { return point_bins_; }
  const uint32_t* line_bin_offsets() const { return line_bins_; }

 private:
  const AspectHeader* header_ = nullptr;
  const Model* models_ = nullptr;
  const AspectRecord* aspects_ = nullptr;
  const AspectBasis* bases_ = nullptr;
  const uint32_t* point_bins_ = nullptr;
  const AspectPointEntry* point_entries_ = nullptr;
  const uint32_t* line_bins_ = nullptr;
  const AspectLineEntry* line_entries_ = nullptr;
};

}  // namespace sh
