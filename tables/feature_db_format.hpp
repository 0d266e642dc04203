// The texture feature database blob: what recognition of printed (textured) models needs,
// learnt offline from the models' artwork and laid out to be used in place (memory-mapped, or a
// section of a model-set blob). See docs/tables.md.
//
// Layout (little-endian; every section starts at a multiple of kSectionAlignment bytes):
//
//   FeatureDbHeader                      fixed size, at offset 0
//   Model[n_models]                      geometry of each printed model (recog/model/model.hpp)
//   TexturedFace[n_faces]                each printed face: frame, polygon, texture image
//   FaceView[n_views]                    each learnt view of a face: frontal or an affine tilt
//   FeatureRecord[n_features]            each learnt feature: view, position, model point
//   TextureDescriptor[n_features]        its descriptor (same order)
//   KdNode[n_nodes]                      kd-tree over the descriptors (tables/texture_records.hpp)
//   uint8 texels[n_texel_bytes]          grey face textures for verification, row-major
//
// The CRC-32 covers every byte of the blob, its own field read as zero (BlobCrc32).
#pragma once

#include <cstddef>
#include <cstdint>
#include <type_traits>

#include "recog/model/model.hpp"
#include "tables/blob_checks.hpp"
#include "tables/table_format.hpp"
#include "tables/texture_records.hpp"

namespace sh {

inline constexpr char kFeatureDbMagic[8] = {'S', 'H', 'T', 'E', 'X', 'D', 'B', '\0'};
// Version 3: model edges record whether they are smooth (ModelEdge::smooth). Version 2: the CRC
// covers the header too, reserved fields must be zero.
inline constexpr uint16_t kFeatureDbFormatVersion = 3;

// Capacities the recogniser's memory is sized for; the reader refuses larger databases.
inline constexpr uint32_t kMaxFeatureDbModels = 16;
inline constexpr uint32_t kMaxFeatureDbFaces = 128;
inline constexpr uint32_t kMaxFeatureDbViews = 2048;
inline constexpr uint32_t kMaxFeatureDbFeatures = 262144;
inline constexpr uint32_t kMaxFeatureDbNodes = 2 * kMaxFeatureDbFeatures;
inline constexpr uint64_t kMaxFeatureDbTexelBytes = 64ull << 20;
inline constexpr int kMaxFaceTextureSide = 4096;    // texels per side of one face texture
inline constexpr int kMaxTexturedFaceCorners = 16;  // corners of a printed face's polygon

// Settings the features were learnt with; recognition extracts its features with the same.
struct FeatureDbExtraction {
  uint32_t levels;
  float input_sigma_px, level_sigma_px, integration_sigma_px, harris_k, min_response;
  uint32_t nms_radius_px;
  float orientation_sigma_px, secondary_orientation_ratio;
  uint32_t max_orientations;
};
static_assert(sizeof(FeatureDbExtraction) == 40);

struct FeatureDbHeader {
  char magic[8];
  uint16_t format_version;
  uint16_t descriptor_size;  // kDescriptorSize
  uint32_t header_size;      // sizeof(FeatureDbHeader)
  uint64_t total_size;       // whole blob in bytes
  uint32_t blob_crc32;       // BlobCrc32 of bytes [0, total_size)
  uint32_t n_models;
  uint32_t n_faces;
  uint32_t n_views;
  uint32_t n_features;
  uint32_t n_nodes;
  uint64_t n_texel_bytes;
  float feature_px_per_mm;  // resolution of the rectified faces the features were learnt on
  float texture_px_per_mm;  // resolution of the stored face textures
  FeatureDbExtraction extraction;
  SectionRef models, faces, views, features, descriptors, nodes, texels;
  uint8_t reserved[40];  // zero; pads the header to 256 bytes
};
static_assert(sizeof(FeatureDbHeader) == 256, "header layout is part of the format");
static_assert(offsetof(FeatureDbHeader, blob_crc32) == kBlobCrc32Offset);
static_assert(std::is_standard_layout_v<FeatureDbHeader>);

// A printed face. Face frame: model point = origin + a * axis_a + b * axis_b (millimetres), with
// axis_a x axis_b the outward normal, so that seen from outside a runs right and b up. Texture
// texel (i, j) covers a in min_a + [i, i + 1] / texture_px_per_mm and b in
// max_b - [j + 1, j] / texture_px_per_mm (row 0 at the top, as an image of the face seen from
// outside).
struct TexturedFace {
  uint16_t model;      // index into the model directory
  uint8_t model_face;  // face index in that Model
  uint8_t n_corners;   // polygon corners (the Model face's vertices, same order)
  float origin_mm[3];
  float axis_a[3];
  float axis_b[3];
  float corners_ab_mm[kMaxTexturedFaceCorners][2];
  float min_ab_mm[2];
  float max_ab_mm[2];
  uint64_t texel_offset;  // into the texel section
  uint16_t texel_width;
  uint16_t texel_height;
  uint32_t n_features;  // learnt on this face, all views
};
static_assert(sizeof(TexturedFace) == 200);

// One learnt view of a face: the face's rectified image warped by an affine map (identity for
// the frontal view, a tilt otherwise). View pixel coordinates relative to the face centre's
// image: (u, v) = view_from_face * (a - centre_a, b - centre_b).
struct FaceView {
  uint16_t face;  // index into the faces
  uint8_t tilt;   // 0: frontal; k: the k-th tilt of the build settings
  uint8_t reserved;
  float view_from_face[4];  // row-major 2 x 2, view pixels per millimetre
  float centre_ab_mm[2];
};
static_assert(sizeof(FaceView) == 28);

// One learnt feature.
struct FeatureRecord {
  float u_px, v_px;   // position in its view, relative to the face centre's image
  float angle_rad;    // orientation in the view
  float scale;        // view pixels per level pixel
  float model_mm[3];  // the point on the model
  uint16_t view;      // index into the views
  uint8_t level;      // pyramid level it was found on
  uint8_t reserved;
};
static_assert(sizeof(FeatureRecord) == 32);

}  // namespace sh
