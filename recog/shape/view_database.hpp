// The view database of the shape path (seed 001 sections IV-C, IV-D): for every colour model,
// size-normalised windows of silhouettes rendered over the viewing sphere and the in-plane
// rotation, compressed by PCA, each with the orientation it was rendered at.
//
// Blob layout (little-endian, sections 64-byte aligned, used in place like the table blob):
//
//   ShapeViewsHeader                  256 bytes at offset 0
//   Model[n_models]                   the models (recog/model/model.hpp), symmetry groups filled
//   ShapeModelRecord[n_models]        colour and view range of each model
//   float mean[window_pixels]         PCA mean window
//   int16 basis[n_components][window_pixels]         Q2.14 unit basis vectors
//   ShapeViewRecord[n_views]          orientation, model and extent of each view
//   int16 coefficients[n_views][component_stride]    Q3.13 PCA coefficients, zero padded
//
// The CRC-32 covers every byte of the blob, its own field read as zero (BlobCrc32). docs/shape.md
// describes every field.
#pragma once

#include <cstddef>
#include <cstdint>
#include <type_traits>

#include "recog/base/blob_start.hpp"
#include "recog/base/fixed_point.hpp"
#include "recog/base/status.hpp"
#include "recog/base/vector.hpp"
#include "recog/model/model.hpp"
#include "recog/shape/shape_window.hpp"

namespace sh {

static_assert(__BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__, "blobs are read in place: little-endian");

inline constexpr char kShapeViewsMagic[8] = {'S', 'H', 'V', 'I', 'E', 'W', 'S', '\0'};
// Version 2: the CRC covers the header too, reserved fields must be zero.
inline constexpr uint16_t kShapeViewsVersion = 2;
inline constexpr size_t kShapeSectionAlignment = 64;

// Capacities the recogniser is sized for; larger databases are refused at load.
inline constexpr uint32_t kMaxShapeModels = 16;
inline constexpr uint32_t kMaxShapeViews = 131072;
inline constexpr uint32_t kMaxShapeComponents = 128;

// Fixed-point formats: coefficients Q3.13 (|c| < 4; a unit-energy window minus the mean has
// coefficients below 2), basis entries and quaternions Q2.14 like the table's unit vectors.
using QCoefficient = Q<3, 13>;
using QBasis = Q<2, 14>;
using QQuaternion = Q<2, 14>;
using UQExtentMm = UQ<8, 8>;

struct ShapeSection {
  uint64_t offset;  // from the start of the blob
  uint64_t size;    // bytes
};

struct ShapeViewsHeader {
  char magic[8];
  uint16_t format_version;
  uint16_t window_side;  // kWindowSide the views were normalised to
  uint32_t header_size;  // sizeof(ShapeViewsHeader)
  uint64_t total_size;
  uint32_t blob_crc32;  // BlobCrc32 of bytes [0, total_size)
  uint32_t n_models;
  uint32_t n_views;
  uint16_t n_components;      // PCA dimensions
  uint16_t component_stride;  // int16 per view row: n_components rounded up to 8
  // The camera the views were rendered with: the model's origin on the optical axis at this
  // distance, this focal length (information; extents are already in millimetres).
  float render_focal_px;
  float render_distance_mm;
  float view_spacing_deg;  // sampling step over the viewing sphere and the in-plane rotation
  float explained_energy;  // share of the views' variance the components keep (information)
  uint32_t reserved0;
  ShapeSection models, shape_models, mean, basis, views, coefficients;
  uint8_t reserved1[96];  // zero; pads the header to 256 bytes
};
static_assert(sizeof(ShapeViewsHeader) == 256, "header layout is part of the format");
static_assert(offsetof(ShapeViewsHeader, blob_crc32) == kBlobCrc32Offset);
static_assert(std::is_standard_layout_v<ShapeViewsHeader>);

struct ShapeModelRecord {
  float kd[3];          // diffuse colour (MTL Kd), linear 0..1
  float radius_mm;      // largest distance of a corner from the model origin
  uint32_t first_view;  // views [first_view, first_view + n_views) belong to this model
  uint32_t n_views;
  uint32_t reserved[2];
};
static_assert(sizeof(ShapeModelRecord) == 32);

// One rendered view. `q` is the orientation of the model in the ray frame of the view: the
// frame whose z axis is the viewing ray through the model origin (see RayFrame()), so that
// cam_R_model = cam_R_ray * ray_R_model wherever the object is.
struct ShapeViewRecord {
  QQuaternion::Raw q[4];         // unit quaternion w, x, y, z of ray_R_model, Q2.14
  uint16_t model;                // index into the database's models
  UQExtentMm::Raw extent_mm[2];  // silhouette box width, height at the origin's depth, UQ8.8 mm
  uint16_t reserved;
};
static_assert(sizeof(ShapeViewRecord) == 16);

inline constexpr size_t AlignShapeSection(size_t n) {
  return (n + kShapeSectionAlignment - 1) / kShapeSectionAlignment * kShapeSectionAlignment;
}

struct ViewMatch {
  uint32_t view = 0;
  float distance2 = 0;  // squared distance in PCA space
};

// Projection of a window into PCA space, as raw Q3.13 coefficients (component_stride entries,
// padding zero).
struct ShapeCoefficients {
  QCoefficient::Raw c[kMaxShapeComponents] = {};
};

// c_k = basis_k . (window - mean) for k < n_components (basis rows of kWindowPixels Q2.14 raw
// entries), stored as raw Q3.13 (saturating); entries n_components .. stride - 1 are zero. The
// builder and ShapeViewsView::Project both use it.
void ProjectShapeWindow(const float* mean, const QBasis::Raw* basis, int n_components, int stride,
                        const ShapeWindow& window, ShapeCoefficients* out);

// Components summed together by the projection; a share of the projection is whole blocks.
inline constexpr int kProjectBlock = 8;

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

  // PCA coefficients of a window.
  void Project(const ShapeWindow& window, ShapeCoefficients* out) const;
  // Share `share` of `shares` of Project's coefficients (contiguous blocks of kProjectBlock
  // components; the last share writes the padding): the same values bit for bit, so that
  // `shares` threads together write what Project writes.
  void ProjectShare(const ShapeWindow& window, int share, int shares, ShapeCoefficients* out) const;

  // The `k` nearest views among the models whose bit is set in `model_mask`, nearest first
  // (exhaustive, with partial-distance early exit: views go in groups of four, and a group is
  // abandoned once every running sum in it reaches the k-th best so far; the components come in
  // decreasing variance, so most views are abandoned after a few blocks). Of equal distances
  // the earlier view comes first.
  void Nearest(const ShapeCoefficients& query, uint32_t model_mask, size_t k,
               Vector<ViewMatch>& out) const;

 private:
  const ShapeViewsHeader* header_ = nullptr;
  const Model* models_ = nullptr;
  const ShapeModelRecord* shape_models_ = nullptr;
  const float* mean_ = nullptr;
  const QBasis::Raw* basis_ = nullptr;
  const ShapeViewRecord* views_ = nullptr;
  const QCoefficient::Raw* coefficients_ = nullptr;
};

// The ray frame of a point: z along the viewing ray from the camera centre through x_cam_mm,
// turned from the camera frame by the smallest rotation (so on the optical axis it is the
// camera frame, and the image axes keep their directions nearby). Returns cam_R_ray.
Eigen::Matrix3f RayFrame(const Eigen::Vector3f& x_cam_mm);

}  // namespace sh
