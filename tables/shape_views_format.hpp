// The view database blob of the shape path (seed 001 sections IV-C, IV-D): for every colour model,
// size-normalised windows of silhouettes rendered over the viewing sphere and the in-plane
// rotation, compressed by PCA, each with the orientation it was rendered at.
//
// Blob layout (little-endian, sections kSectionAlignment-aligned, used in place like the table
// blob):
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

#include "recog/base/fixed_point.hpp"
#include "recog/model/model.hpp"
#include "tables/blob_checks.hpp"

namespace sh {

// The side of the size-normalised silhouette windows the views are stored as (k of eq. 1 of
// seed 001; recog/shape/shape_window.hpp makes them).
inline constexpr int kShapeViewWindowSide = 64;
inline constexpr int kShapeViewWindowPixels = kShapeViewWindowSide * kShapeViewWindowSide;

inline constexpr char kShapeViewsMagic[8] = {'S', 'H', 'V', 'I', 'E', 'W', 'S', '\0'};
// Version 3: model edges record whether they are smooth (ModelEdge::smooth). Version 2: the CRC
// covers the header too, reserved fields must be zero.
inline constexpr uint16_t kShapeViewsVersion = 3;

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

struct ShapeViewsHeader {
  char magic[8];
  uint16_t format_version;
  uint16_t window_side;  // kShapeViewWindowSide
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
  SectionRef models, shape_models, mean, basis, views, coefficients;
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

}  // namespace sh
