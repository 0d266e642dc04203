#include "tables/aspect_view.hpp"

#include <cmath>
#include <cstddef>
#include <cstring>

#include "recog/base/crc32.hpp"
#include "tables/blob_checks.hpp"

namespace sh {
namespace {

Status CorruptAspect(const char* what) {
  return Status::Error(StatusCode::kDataLoss, "aspect table corrupt: %s", what);
}

Status CheckGrid(const Grid2d& g, const char* name) {
  const bool finite = std::isfinite(g.min[0]) && std::isfinite(g.min[1]) && std::isfinite(g.bin);
  if (!finite || !(g.bin > 0.0f) || g.dims[0] == 0 || g.dims[1] == 0 ||
      g.dims[0] > kMaxAspectGridSide || g.dims[1] > kMaxAspectGridSide ||
      g.bin_count() > kMaxAspectBins) {
    return Status::Error(StatusCode::kDataLoss, "aspect table corrupt: bad %s grid geometry", name);
  }
  return Status::Ok();
}

bool AllFinite(const float* v, int n) {
  for (int i = 0; i < n; ++i) {
    if (!std::isfinite(v[i])) return false;
  }
  return true;
}

}  // namespace

Result<AspectTableView> AspectTableView::Open(const void* blob, size_t size) {
  SH_RETURN_IF_ERROR(CheckBlobHeader(
      blob, size, {"aspect table", kAspectMagic, kAspectFormatVersion, sizeof(AspectHeader), 8}));
  const auto* bytes = static_cast<const uint8_t*>(blob);
  const auto* h = reinterpret_cast<const AspectHeader*>(bytes);
  if (!IsValidAspectBasisKind(h->basis_kind)) return CorruptAspect("basis kind not 1 or 2");
  if (h->reserved0 != 0 || !AllZero(h->build.reserved, sizeof(h->build.reserved)) ||
      (h->build.flags & ~kAspectEdgeBasesOnly) != 0) {
    return CorruptAspect("reserved header bits not zero");
  }
  if (h->n_models == 0 || h->n_models > kMaxAspectModels) {
    return Status::Error(StatusCode::kOutOfRange, "aspect table has %u models (1..%u supported)",
                         h->n_models, kMaxAspectModels);
  }
  if (h->n_aspects > kMaxAspects || h->n_bases > kMaxAspectBases ||
      h->n_point_entries > kMaxAspectPointEntries || h->n_line_entries > kMaxAspectLineEntries) {
    return Status::Error(StatusCode::kOutOfRange,
                         "aspect table larger than this build supports (%u aspects, %u bases, %u "
                         "point and %u line entries; limits %u, %u, %u, %u)",
                         h->n_aspects, h->n_bases, h->n_point_entries, h->n_line_entries,
                         kMaxAspects, kMaxAspectBases, kMaxAspectPointEntries,
                         kMaxAspectLineEntries);
  }
  SH_RETURN_IF_ERROR(CheckGrid(h->point_grid, "point"));
  SH_RETURN_IF_ERROR(CheckGrid(h->line_grid, "line"));
  if (h->line_angle_slices == 0 || h->line_angle_slices > kMaxAspectAngleSlices ||
      h->size_slices == 0 || h->size_slices > kMaxAspectAngleSlices ||
      !std::isfinite(h->log_size_min) || !std::isfinite(h->log_size_max) ||
      !(h->log_size_max > h->log_size_min) ||
      uint64_t{h->size_slices} * h->point_grid.bin_count() > kMaxAspectBins ||
      uint64_t{h->size_slices} * h->line_angle_slices * h->line_grid.bin_count() > kMaxAspectBins) {
    return CorruptAspect("bin slices out of range");
  }
  const uint32_t point_bins = h->size_slices * h->point_grid.bin_count();
  const uint32_t line_bins = h->size_slices * h->line_angle_slices * h->line_grid.bin_count();
  const uint64_t total = h->total_size;
  SH_RETURN_IF_ERROR(
      CheckSection(h->models, h->n_models, sizeof(Model), total, "aspect table", "model"));
  SH_RETURN_IF_ERROR(CheckSection(h->aspects, h->n_aspects, sizeof(AspectRecord), total,
                                  "aspect table", "aspect"));
  SH_RETURN_IF_ERROR(
      CheckSection(h->bases, h->n_bases, sizeof(AspectBasis), total, "aspect table", "basis"));
  SH_RETURN_IF_ERROR(CheckSection(h->point_bins, point_bins + 1, sizeof(uint32_t), total,
                                  "aspect table", "point bin"));
  SH_RETURN_IF_ERROR(CheckSection(h->point_entries, h->n_point_entries, sizeof(AspectPointEntry),
                                  total, "aspect table", "point entry"));
  SH_RETURN_IF_ERROR(CheckSection(h->line_bins, line_bins + 1, sizeof(uint32_t), total,
                                  "aspect table", "line bin"));
  SH_RETURN_IF_ERROR(CheckSection(h->line_entries, h->n_line_entries, sizeof(AspectLineEntry),
                                  total, "aspect table", "line entry"));

  AspectTableView v;
  v.header_ = h;
  v.models_ = reinterpret_cast<const Model*>(bytes + h->models.offset);
  v.aspects_ = reinterpret_cast<const AspectRecord*>(bytes + h->aspects.offset);
  v.bases_ = reinterpret_cast<const AspectBasis*>(bytes + h->bases.offset);
  v.point_bins_ = reinterpret_cast<const uint32_t*>(bytes + h->point_bins.offset);
  v.point_entries_ = reinterpret_cast<const AspectPointEntry*>(bytes + h->point_entries.offset);
  v.line_bins_ = reinterpret_cast<const uint32_t*>(bytes + h->line_bins.offset);
  v.line_entries_ = reinterpret_cast<const AspectLineEntry*>(bytes + h->line_entries.offset);

  for (uint32_t i = 0; i < h->n_models; ++i) SH_RETURN_IF_ERROR(CheckModelRecord(v.models_[i], i));
  for (uint32_t i = 0; i < h->n_aspects; ++i) {
    const AspectRecord& a = v.aspects_[i];
    if (a.model >= h->n_models) return CorruptAspect("aspect refers to a missing model");
    if (!AllFinite(a.dir_model, 3) || !AllFinite(a.cam_T_model, 12) ||
        !std::isfinite(a.distance_mm) || !(a.distance_mm > 0.0f) || !std::isfinite(a.radius)) {
      return CorruptAspect("aspect geometry not finite");
    }
    if (a.first_basis > h->n_bases || a.n_bases > h->n_bases - a.first_basis) {
      return CorruptAspect("aspect basis range past the bases");
    }
  }
  const int n_basis_corners = BasisCornerCount(static_cast<AspectBasisKind>(h->basis_kind));
  for (uint32_t i = 0; i < h->n_bases; ++i) {
    const AspectBasis& b = v.bases_[i];
    if (b.aspect >= h->n_aspects) return CorruptAspect("basis refers to a missing aspect");
    const AspectRecord& a = v.aspects_[b.aspect];
    if (b.model != a.model || i < a.first_basis || i >= a.first_basis + a.n_bases) {
      return CorruptAspect("basis and its aspect disagree");
    }
    for (int k = 0; k < n_basis_corners; ++k) {
      if (b.corners[k] >= v.models_[b.model].n_corners) return CorruptAspect("basis corner index");
    }
    if (!AllFinite(b.origin, 2) || !AllFinite(b.axes, 4))
      return CorruptAspect("basis frame not finite");
    const float det = b.axes[0] * b.axes[3] - b.axes[1] * b.axes[2];
    if (!(std::fabs(det) > 0.0f)) return CorruptAspect("basis frame singular");
  }
  SH_RETURN_IF_ERROR(CheckBinOffsets(v.point_bins_, point_bins, h->n_point_entries, "point"));
  SH_RETURN_IF_ERROR(CheckBinOffsets(v.line_bins_, line_bins, h->n_line_entries, "line"));
  for (uint32_t i = 0; i < h->n_point_entries; ++i) {
    if (v.point_entries_[i].basis >= h->n_bases) return CorruptAspect("point entry basis index");
  }
  for (uint32_t i = 0; i < h->n_line_entries; ++i) {
    if (v.line_entries_[i].basis >= h->n_bases) return CorruptAspect("line entry basis index");
  }
  return v;
}

int AspectTableView::FindModel(const char* name) const {
  for (uint32_t i = 0; i < header_->n_models; ++i) {
    if (std::strncmp(models_[i].name, name, kMaxModelNameLength + 1) == 0) {
      return static_cast<int>(i);
    }
  }
  return -1;
}

}  // namespace sh
