// Read-only, validated, zero-copy access to a table blob (table_format.hpp).
//
// Open() checks everything a corrupt, truncated or foreign blob could get wrong before any
// pointer into it is handed out; afterwards accessors are plain pointer arithmetic. The blob
// memory must outlive the view and be at least 8-byte aligned (mmap and the linked-in tables
// are 64-byte aligned).
#pragma once

#include <cstddef>
#include <cstdint>

#include "recog/base/status.hpp"
#include "tables/table_format.hpp"

namespace sh {

template <typename T>
struct ConstSpan {
  const T* data = nullptr;
  size_t size = 0;
  const T* begin() const { return data; }
  const T* end() const { return data + size; }
  const T& operator[](size_t i) const { return data[i]; }
};

// Checks bin offsets [0, bins]: from 0 to `entries`, never decreasing.
Status CheckBinOffsets(const uint32_t* offsets, uint32_t bins, uint32_t entries, const char* name);

// Checks a model record read from a blob: a NUL-terminated name, counts within the capacities,
// finite corners, edge and face indices in range. `index` names it in the message.
Status CheckModelRecord(const Model& model, uint32_t index);

class TableView {
 public:
  TableView() = default;
  static Result<TableView> Open(const void* blob, size_t size);

  // True for a default-constructed view (no blob opened): it has no models and no bases, and
  // only model_count() and basis_count() may be called on it.
  bool empty() const { return header_ == nullptr; }

  const TableHeader& header() const { return *header_; }
  HashFunction hash_function() const { return static_cast<HashFunction>(header_->hash_function); }
  BasisLimits limits() const;

  uint32_t model_count() const { return header_ != nullptr ? header_->n_models : 0; }
  const Model& model(uint32_t i) const { return models_[i]; }
  // Index of the model with this name, or -1.
  int FindModel(const char* name) const;

  uint32_t basis_count() const { return header_ != nullptr ? header_->n_bases : 0; }
  const BasisRecord& basis(uint32_t i) const { return bases_[i]; }

  const GridGeometry& point_grid() const { return header_->point_grid; }
  const GridGeometry& line_grid() const { return header_->line_grid; }
  uint32_t point_entry_count() const { return header_->n_point_entries; }
  uint32_t line_entry_count() const { return header_->n_line_entries; }
  const PointEntry* point_entries() const { return point_entries_; }
  const LineEntry* line_entries() const { return line_entries_; }
  const uint32_t* point_bin_offsets() const { return point_bins_; }
  const uint32_t* line_bin_offsets() const { return line_bins_; }

  ConstSpan<PointEntry> point_bin(uint32_t bin) const {
    return {point_entries_ + point_bins_[bin], point_bins_[bin + 1] - point_bins_[bin]};
  }
  ConstSpan<LineEntry> line_bin(uint32_t bin) const {
    return {line_entries_ + line_bins_[bin], line_bins_[bin + 1] - line_bins_[bin]};
  }

 private:
  const TableHeader* header_ = nullptr;
  const Model* models_ = nullptr;
  const BasisRecord* bases_ = nullptr;
  const uint32_t* point_bins_ = nullptr;
  const PointEntry* point_entries_ = nullptr;
  const uint32_t* line_bins_ = nullptr;
  const LineEntry* line_entries_ = nullptr;
};

}  // namespace sh
