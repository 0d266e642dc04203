// The aspect table: 2-D geometric hashing arrays over the aspect models of a model set (thesis
// ch. 6), laid out to be used in place like the 3-D table blob (table_format.hpp).
//
// Layout (little-endian, every section at a multiple of kSectionAlignment bytes):
//
//   AspectHeader                      fixed size, at offset 0
//   Model[n_models]                   model directory (recog/model/model.hpp)
//   AspectRecord[n_aspects]           one per stored view of a model
//   AspectBasis[n_bases]              one per model basis (ordered corner pair or triple)
//   uint32 point_bin_offsets[point bins + 1]
//   AspectPointEntry[n_point_entries] grouped by bin: basis size slice, then position
//   uint32 line_bin_offsets[line bins + 1]
//   AspectLineEntry[n_line_entries]   grouped by bin: size slice, direction slice, centre
//
// The CRC-32 covers every byte of the blob, its own field read as zero (BlobCrc32). See
// docs/tables.md ("Aspect tables").
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <type_traits>

#include "recog/base/fixed_point.hpp"
#include "recog/model/model.hpp"
#include "tables/blob_checks.hpp"
#include "tables/table_format.hpp"

namespace sh {

inline constexpr char kAspectMagic[8] = {'S', 'H', 'A', 'S', 'P', 'E', 'C', 'T'};
// Version 3: model edges record whether they are smooth (ModelEdge::smooth). Version 2: the CRC
// covers the header too, reserved fields must be zero.
inline constexpr uint16_t kAspectFormatVersion = 3;

// Capacities the monocular recogniser's scratch memory is sized for; larger tables are refused
// at load (and by the builder).
inline constexpr uint32_t kMaxAspectModels = kMaxTableModels;
inline constexpr uint32_t kMaxAspects = 8192;
inline constexpr uint32_t kMaxAspectBases = 131072;
inline constexpr uint32_t kMaxAspectPointEntries = 262144;
inline constexpr uint32_t kMaxAspectLineEntries = 262144;
inline constexpr uint32_t kMaxAspectBins = 262144;
inline constexpr uint32_t kMaxAspectAngleSlices = 64;
inline constexpr uint16_t kMaxAspectGridSide = 1024;  // bins along either axis of a grid

// How a basis fixes the 2-D transformation (thesis 6.2).
enum class AspectBasisKind : uint8_t {
  kSimilarity = 1,  // two corners: origin at their midpoint, unit x from the first to the second
  kAffine = 2,      // three corners: origin at their centroid, axes p1 - p0 and p2 - p0
};

inline bool IsValidAspectBasisKind(unsigned kind) { return kind == 1 || kind == 2; }
inline int BasisCornerCount(AspectBasisKind kind) {
  return kind == AspectBasisKind::kSimilarity ? 2 : 3;
}

// Hash coordinates: the basis frame's dimensionless coordinates in Q4.12 (+-8, 1/4096).
using QHash = Q<4, 12>;
// Lengths in hash units: unsigned Q4.12 (0 .. 16).
using UQHashLength = UQ<4, 12>;

// A uniform grid of square bins over a rectangle of hash space.
struct Grid2d {
  float min[2];  // corner of bin (0, 0), hash units
  float bin;     // edge length of a bin, hash units
  uint16_t dims[2];
  uint32_t bin_count() const { return uint32_t{dims[0]} * dims[1]; }
};
static_assert(sizeof(Grid2d) == 16);

// How the aspects were made and checked (thesis 6.3, 6.4.1); stored for information and so
// that recognition uses the same limits.
struct AspectBuildParams {
  float initial_spacing_deg;   // initial grid on the viewing sphere
  float distance_factor;       // virtual camera distance in mean corner radii
  float min_corner_angle_deg;  // 2-D corners: angle between visible edges
  float min_segment_fraction;  // shortest segment, fraction of the aspect's extent
  float min_basis_fraction;    // shortest basis side, fraction of the aspect's radius
  float test_sigma_point_px;   // vote widths of the refinement test, at the test scale
  float test_sigma_line_px;
  float test_scale_px;       // test views are scaled to this radius in pixels
  float test_vote_fraction;  // a test basis passes with this fraction of the maximum vote
  float test_pass_fraction;  // a test view passes when this fraction of its bases pass
  uint8_t max_levels;        // refinement levels
  uint8_t flags;             // kAspectEdgeBasesOnly
  uint8_t reserved[2];
};

// AspectBuildParams::flags: bases only over corners joined by visible edges.
inline constexpr uint8_t kAspectEdgeBasesOnly = 1;
static_assert(sizeof(AspectBuildParams) == 44);

struct AspectHeader {
  char magic[8];
  uint16_t format_version;
  uint8_t basis_kind;  // AspectBasisKind
  uint8_t reserved0;
  uint32_t header_size;  // sizeof(AspectHeader)
  uint64_t total_size;   // whole blob in bytes
  uint32_t blob_crc32;   // BlobCrc32 of bytes [0, total_size)
  uint32_t n_models;
  uint32_t n_aspects;
  uint32_t n_bases;
  uint32_t n_point_entries;
  uint32_t n_line_entries;
  uint32_t max_point_bin_entries;
  uint32_t max_line_bin_entries;
  Grid2d point_grid;
  Grid2d line_grid;
  AspectBuildParams build;
  // Bins are sliced by the apparent size of their entry's basis (AspectApparentSizeMm), in
  // size_slices equal steps of its logarithm over [log_size_min, log_size_max], and line bins
  // also by the segment's direction modulo 180 degrees in line_angle_slices. Point bin:
  // (size * dims[1] + y) * dims[0] + x; line bin: ((size * line_angle_slices + angle) *
  // dims[1] + y) * dims[0] + x.
  uint16_t line_angle_slices;
  uint16_t size_slices;
  float log_size_min, log_size_max;
  SectionRef models, aspects, bases, point_bins, point_entries, line_bins, line_entries;
};
static_assert(sizeof(AspectHeader) == 256, "header layout is part of the format");
static_assert(offsetof(AspectHeader, blob_crc32) == kBlobCrc32Offset);
static_assert(std::is_standard_layout_v<AspectHeader>);

// One view of one model.
struct AspectRecord {
  uint16_t model;
  uint8_t level;        // refinement level of the view (0: initial grid)
  uint8_t n_corners;    // 2-D corners in this aspect
  uint16_t n_segments;  // 2-D segments
  uint16_t reserved;
  float dir_model[3];     // unit vector from the centroid towards the virtual camera
  float cam_T_model[12];  // virtual camera: row-major R (9) then t_mm (3)
  float distance_mm;      // virtual camera to centroid
  float radius;           // largest normalised distance of a 2-D corner from the image origin
  uint32_t first_basis;   // bases [first_basis, first_basis + n_bases) belong to this aspect
  uint32_t n_bases;
};
static_assert(sizeof(AspectRecord) == 84);

// One model basis: corners of one aspect, and the basis frame in the aspect's normalised image
// coordinates: x_aspect = origin + axes * h for hash coordinates h.
struct AspectBasis {
  uint32_t aspect;
  uint16_t model;
  uint8_t corners[3];  // model corner indices; corners[2] unused (0xff) for similarity bases
  uint8_t reserved;
  uint16_t n_point_entries;  // entries this basis stored: the vote normalisers
  uint16_t n_line_entries;
  uint16_t reserved2;
  float origin[2];
  float axes[4];  // column-major 2 x 2: first column the image of h = (1, 0)
};
static_assert(sizeof(AspectBasis) == 40);

// A 2-D corner in a basis frame (Q4.12 hash units).
struct AspectPointEntry {
  QHash::Raw x, y;
  uint32_t basis;
};
static_assert(sizeof(AspectPointEntry) == 8);

// A 2-D segment in a basis frame: centre (Q4.12), unit direction (Q2.14), length (UQ4.12).
// Binned by its direction and centre: a scene line looks up the centres near it (a strip of
// bins along it) in the direction slices near its own, instead of the support vectors the 3-D
// tables use, whose bins near the origin collect every edge that meets a basis corner.
struct AspectLineEntry {
  QHash::Raw cx, cy;
  QUnit::Raw vx, vy;
  uint16_t length;
  uint16_t reserved;
  uint32_t basis;
};
static_assert(sizeof(AspectLineEntry) == 16);

// The apparent size of a basis: its size in the aspect's normalised image (square root of the
// frame's area scale) times the virtual camera distance, millimetres. Seen at depth Z with focal
// length f, the basis is about f * size / Z pixels large.
inline float AspectApparentSizeMm(const AspectRecord& aspect, const AspectBasis& basis) {
  const float det = basis.axes[0] * basis.axes[3] - basis.axes[1] * basis.axes[2];
  return std::sqrt(std::fabs(det)) * aspect.distance_mm;
}

// Size slice of an apparent size (clamped to the table's range).
inline uint32_t SizeSlice(float size_mm, float log_min, float log_max, uint32_t slices) {
  const float t = (std::log(std::max(size_mm, 1e-6f)) - log_min) / (log_max - log_min);
  const float k = std::floor(t * static_cast<float>(slices));
  if (!(k >= 0.0f)) return 0;  // also NaN
  return k < static_cast<float>(slices) ? static_cast<uint32_t>(k) : slices - 1;
}

// Direction slice of a line with direction (dx, dy), modulo 180 degrees, of `slices`.
inline uint32_t LineAngleSlice(float dx, float dy, uint32_t slices) {
  constexpr float kPi = 3.14159265358979f;
  float angle = std::atan2(dy, dx);
  if (angle < 0) angle += kPi;
  if (angle >= kPi) angle -= kPi;
  const uint32_t k = static_cast<uint32_t>(angle / kPi * static_cast<float>(slices));
  return k < slices ? k : slices - 1;
}

}  // namespace sh
