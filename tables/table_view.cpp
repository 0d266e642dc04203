#include "tables/table_view.hpp"

#include <cmath>
#include <cstddef>
#include <cstring>

#include "recog/base/crc32.hpp"
#include "recog/model/model_check.hpp"
#include "tables/blob_checks.hpp"

namespace sh {
namespace {

Status CorruptTable(const char* what) {
  return Status::Error(StatusCode::kDataLoss, "table blob corrupt: %s", what);
}

Status CheckGrid(const GridGeometry& g, const char* name) {
  const bool finite = std::isfinite(g.min_mm[0]) && std::isfinite(g.min_mm[1]) &&
                      std::isfinite(g.min_mm[2]) && std::isfinite(g.bin_mm);
  if (!finite || !(g.bin_mm > 0.0f) || g.dims[0] == 0 || g.dims[1] == 0 || g.dims[2] == 0 ||
      g.bin_count() > kMaxTableBins)
    return Status::Error(StatusCode::kDataLoss, "table blob corrupt: bad %s grid geometry", name);
  return Status::Ok();
}

// The basis limits are distances and angles the scene bases are built with: finite, not negative.
Status CheckLimits(const TableHeader& h) {
  const float limits[] = {h.min_point_line_mm,     h.max_point_line_mm,    h.min_line_angle_deg,
                          h.max_line_distance_mm,  h.min_point_spacing_mm, h.max_point_spacing_mm,
                          h.min_triangle_height_mm};
  for (float f : limits) {
    if (!std::isfinite(f) || f < 0.0f)
      return CorruptTable("basis limits not finite and non-negative");
  }
  return Status::Ok();
}

}  // namespace

uint32_t TableBlobCrc32(const uint8_t* blob, size_t size) {
  return BlobCrc32(blob, size, offsetof(TableHeader, blob_crc32));
}

Status CheckBinOffsets(const uint32_t* offsets, uint32_t bins, uint32_t entries, const char* name) {
  if (offsets[0] != 0 || offsets[bins] != entries) {
    return Status::Error(StatusCode::kDataLoss,
                         "table blob corrupt: %s bin offsets do not cover the entries", name);
  }
  for (uint32_t i = 0; i < bins; ++i) {
    if (offsets[i + 1] < offsets[i]) {
      return Status::Error(StatusCode::kDataLoss,
                           "table blob corrupt: %s bin offsets decrease at bin %u", name, i);
    }
  }
  return Status::Ok();
}

Status CheckModelRecord(const Model& m, uint32_t index) {
  return ValidateModelRecord(m, index, "table blob");
}

Result<TableView> TableView::Open(const void* blob, size_t size) {
  SH_RETURN_IF_ERROR(CheckBlobHeader(
      blob, size, {"table blob", kTableMagic, kTableFormatVersion, sizeof(TableHeader), 8}));
  const auto* bytes = static_cast<const uint8_t*>(blob);
  const auto* h = reinterpret_cast<const TableHeader*>(bytes);
  if (!IsValidHashFunction(h->hash_function)) return CorruptTable("hash function not in 1..5");
  SH_RETURN_IF_ERROR(CheckLimits(*h));
  if (h->n_models == 0 || h->n_models > kMaxTableModels) {
    return Status::Error(StatusCode::kOutOfRange, "table blob has %u models (1..%u supported)",
                         h->n_models, kMaxTableModels);
  }
  if (h->n_bases > kMaxTableBases || h->n_point_entries > kMaxTablePointEntries ||
      h->n_line_entries > kMaxTableLineEntries) {
    return Status::Error(StatusCode::kOutOfRange,
                         "table blob larger than this build supports (%u bases, %u point and %u "
                         "line entries; limits %u, %u, %u)",
                         h->n_bases, h->n_point_entries, h->n_line_entries, kMaxTableBases,
                         kMaxTablePointEntries, kMaxTableLineEntries);
  }
  SH_RETURN_IF_ERROR(CheckGrid(h->point_grid, "point"));
  SH_RETURN_IF_ERROR(CheckGrid(h->line_grid, "line"));
  const uint32_t point_bins = h->point_grid.bin_count(), line_bins = h->line_grid.bin_count();
  const uint64_t total = h->total_size;
  SH_RETURN_IF_ERROR(
      CheckSection(h->models, h->n_models, sizeof(Model), total, "table blob", "model"));
  SH_RETURN_IF_ERROR(
      CheckSection(h->bases, h->n_bases, sizeof(BasisRecord), total, "table blob", "basis"));
  SH_RETURN_IF_ERROR(CheckSection(h->point_bins, point_bins + 1, sizeof(uint32_t), total,
                                  "table blob", "point bin"));
  SH_RETURN_IF_ERROR(CheckSection(h->point_entries, h->n_point_entries, sizeof(PointEntry), total,
                                  "table blob", "point entry"));
  SH_RETURN_IF_ERROR(
      CheckSection(h->line_bins, line_bins + 1, sizeof(uint32_t), total, "table blob", "line bin"));
  SH_RETURN_IF_ERROR(CheckSection(h->line_entries, h->n_line_entries, sizeof(LineEntry), total,
                                  "table blob", "line entry"));

  TableView view;
  view.header_ = h;
  view.models_ = reinterpret_cast<const Model*>(bytes + h->models.offset);
  view.bases_ = reinterpret_cast<const BasisRecord*>(bytes + h->bases.offset);
  view.point_bins_ = reinterpret_cast<const uint32_t*>(bytes + h->point_bins.offset);
  view.point_entries_ = reinterpret_cast<const PointEntry*>(bytes + h->point_entries.offset);
  view.line_bins_ = reinterpret_cast<const uint32_t*>(bytes + h->line_bins.offset);
  view.line_entries_ = reinterpret_cast<const LineEntry*>(bytes + h->line_entries.offset);

  for (uint32_t i = 0; i < h->n_models; ++i)
    SH_RETURN_IF_ERROR(CheckModelRecord(view.models_[i], i));
  for (uint32_t i = 0; i < h->n_bases; ++i) {
    const BasisRecord& b = view.bases_[i];
    if (b.model >= h->n_models) return CorruptTable("basis refers to a missing model");
    for (float f : b.basis_T_model) {
      if (!std::isfinite(f)) return CorruptTable("basis transform not finite");
    }
  }
  SH_RETURN_IF_ERROR(CheckBinOffsets(view.point_bins_, point_bins, h->n_point_entries, "point"));
  SH_RETURN_IF_ERROR(CheckBinOffsets(view.line_bins_, line_bins, h->n_line_entries, "line"));
  for (uint32_t i = 0; i < h->n_point_entries; ++i) {
    if (view.point_entries_[i].basis >= h->n_bases) return CorruptTable("point entry basis index");
  }
  for (uint32_t i = 0; i < h->n_line_entries; ++i) {
    if (view.line_entries_[i].basis >= h->n_bases) return CorruptTable("line entry basis index");
  }
  return view;
}

BasisLimits TableView::limits() const {
  BasisLimits l;
  l.min_point_line_mm = header_->min_point_line_mm;
  l.max_point_line_mm = header_->max_point_line_mm;
  l.min_line_angle_deg = header_->min_line_angle_deg;
  l.max_line_distance_mm = header_->max_line_distance_mm;
  l.min_point_spacing_mm = header_->min_point_spacing_mm;
  l.max_point_spacing_mm = header_->max_point_spacing_mm;
  l.min_triangle_height_mm = header_->min_triangle_height_mm;
  return l;
}

int TableView::FindModel(const char* name) const {
  for (uint32_t i = 0; i < header_->n_models; ++i) {
    if (std::strncmp(models_[i].name, name, kMaxModelNameLength + 1) == 0) return int(i);
  }
  return -1;
}

}  // namespace sh
