#include "tables/feature_db_view.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstring>
#include <iterator>

#include "recog/base/crc32.hpp"
#include "recog/model/model_check.hpp"
#include "tables/blob_checks.hpp"

namespace sh {
namespace {

constexpr const char* kBlob = "feature database";

Status Corrupt(const char* what, uint32_t index) {
  return Status::Error(StatusCode::kDataLoss, "feature database corrupt: %s %u", what, index);
}

bool AllFinite(const float* v, int n) {
  for (int i = 0; i < n; ++i) {
    if (!std::isfinite(v[i])) return false;
  }
  return true;
}

Status CheckFace(const TexturedFace& f, uint32_t i, const Model* models, uint32_t n_models,
                 uint64_t texel_bytes, uint32_t n_features) {
  if (f.model >= n_models) return Corrupt("model index of face", i);
  const Model& m = models[f.model];
  if (f.model_face >= m.n_faces || f.n_corners != m.faces[f.model_face].n_vertices ||
      f.n_corners < 3 || f.n_corners > kMaxTexturedFaceCorners)
    return Corrupt("model face of face", i);
  if (!AllFinite(f.origin_mm, 3) || !AllFinite(f.axis_a, 3) || !AllFinite(f.axis_b, 3) ||
      !AllFinite(&f.corners_ab_mm[0][0], 2 * kMaxTexturedFaceCorners) ||
      !AllFinite(f.min_ab_mm, 2) || !AllFinite(f.max_ab_mm, 2) ||
      !(f.max_ab_mm[0] > f.min_ab_mm[0]) || !(f.max_ab_mm[1] > f.min_ab_mm[1]))
    return Corrupt("geometry of face", i);
  if (f.texel_width == 0 || f.texel_height == 0 || f.texel_width > kMaxFaceTextureSide ||
      f.texel_height > kMaxFaceTextureSide)
    return Corrupt("texture size of face", i);
  const uint64_t bytes = uint64_t{f.texel_width} * f.texel_height;
  if (f.texel_offset > texel_bytes || bytes > texel_bytes - f.texel_offset)
    return Corrupt("texture range of face", i);
  if (f.n_features > n_features) return Corrupt("feature count of face", i);
  return Status::Ok();
}

// The stored extraction settings in the format's ranges. Whether an extractor takes them is the
// texture recogniser's check when it is given the database (TextureFeatureConfig::Validate).
Status CheckExtraction(const FeatureDbExtraction& e) {
  const float values[] = {
      e.input_sigma_px, e.level_sigma_px,       e.integration_sigma_px,       e.harris_k,
      e.min_response,   e.orientation_sigma_px, e.secondary_orientation_ratio};
  if (e.levels < 1 || e.levels > static_cast<uint32_t>(kMaxPyramidLevels) || e.nms_radius_px < 1 ||
      e.max_orientations < 1 || !AllFinite(values, static_cast<int>(std::size(values)))) {
    return Status::Error(StatusCode::kDataLoss,
                         "%s corrupt: extraction settings: %u levels (1..%d), NMS radius %u, %u "
                         "orientations, or a number not finite",
                         kBlob, e.levels, kMaxPyramidLevels, e.nms_radius_px, e.max_orientations);
  }
  return Status::Ok();
}

}  // namespace

Result<FeatureDbView> FeatureDbView::Open(const void* blob, size_t size) {
  SH_RETURN_IF_ERROR(CheckBlobHeader(
      blob, size, {kBlob, kFeatureDbMagic, kFeatureDbFormatVersion, sizeof(FeatureDbHeader), 16}));
  const auto* bytes = static_cast<const uint8_t*>(blob);
  const auto* h = reinterpret_cast<const FeatureDbHeader*>(bytes);
  if (h->descriptor_size != kDescriptorSize) {
    return Status::Error(StatusCode::kDataLoss, "%s corrupt: descriptor size %u, this build's %d",
                         kBlob, h->descriptor_size, kDescriptorSize);
  }
  if (!AllZero(h->reserved, sizeof(h->reserved))) {
    return Status::Error(StatusCode::kDataLoss, "%s corrupt: reserved header bytes not zero",
                         kBlob);
  }
  if (h->n_models == 0 || h->n_models > kMaxFeatureDbModels || h->n_faces == 0 ||
      h->n_faces > kMaxFeatureDbFaces || h->n_views > kMaxFeatureDbViews ||
      h->n_features > kMaxFeatureDbFeatures || h->n_nodes > kMaxFeatureDbNodes ||
      h->n_texel_bytes > kMaxFeatureDbTexelBytes) {
    return Status::Error(StatusCode::kOutOfRange,
                         "%s too large for this build: %u models (max %u), %u faces (max %u), %u "
                         "views (max %u), %u features (max %u)",
                         kBlob, h->n_models, kMaxFeatureDbModels, h->n_faces, kMaxFeatureDbFaces,
                         h->n_views, kMaxFeatureDbViews, h->n_features, kMaxFeatureDbFeatures);
  }
  if ((h->n_features > 0) != (h->n_nodes > 0)) {
    return Status::Error(StatusCode::kDataLoss, "%s corrupt: kd-tree does not match the features",
                         kBlob);
  }
  if (!(std::isfinite(h->feature_px_per_mm) && h->feature_px_per_mm > 0.0f &&
        std::isfinite(h->texture_px_per_mm) && h->texture_px_per_mm > 0.0f))
    return Status::Error(StatusCode::kDataLoss, "%s corrupt: resolution fields", kBlob);
  SH_RETURN_IF_ERROR(CheckExtraction(h->extraction));
  const uint64_t total = h->total_size;
  SH_RETURN_IF_ERROR(CheckSection(h->models, h->n_models, sizeof(Model), total, kBlob, "model"));
  SH_RETURN_IF_ERROR(
      CheckSection(h->faces, h->n_faces, sizeof(TexturedFace), total, kBlob, "face"));
  SH_RETURN_IF_ERROR(CheckSection(h->views, h->n_views, sizeof(FaceView), total, kBlob, "view"));
  SH_RETURN_IF_ERROR(
      CheckSection(h->features, h->n_features, sizeof(FeatureRecord), total, kBlob, "feature"));
  SH_RETURN_IF_ERROR(CheckSection(h->descriptors, h->n_features, sizeof(TextureDescriptor), total,
                                  kBlob, "descriptor"));
  SH_RETURN_IF_ERROR(CheckSection(h->nodes, h->n_nodes, sizeof(KdNode), total, kBlob, "node"));
  SH_RETURN_IF_ERROR(CheckSection(h->texels, h->n_texel_bytes, 1, total, kBlob, "texel"));

  FeatureDbView view;
  view.header_ = h;
  view.models_ = reinterpret_cast<const Model*>(bytes + h->models.offset);
  view.faces_ = reinterpret_cast<const TexturedFace*>(bytes + h->faces.offset);
  view.views_ = reinterpret_cast<const FaceView*>(bytes + h->views.offset);
  view.features_ = reinterpret_cast<const FeatureRecord*>(bytes + h->features.offset);
  view.descriptors_ = reinterpret_cast<const TextureDescriptor*>(bytes + h->descriptors.offset);
  view.nodes_ = reinterpret_cast<const KdNode*>(bytes + h->nodes.offset);
  view.texels_ = bytes + h->texels.offset;

  for (uint32_t i = 0; i < h->n_models; ++i) {
    SH_RETURN_IF_ERROR(ValidateModelRecord(view.models_[i], i, kBlob));
  }
  for (uint32_t i = 0; i < h->n_faces; ++i) {
    SH_RETURN_IF_ERROR(
        CheckFace(view.faces_[i], i, view.models_, h->n_models, h->n_texel_bytes, h->n_features));
  }
  for (uint32_t i = 0; i < h->n_views; ++i) {
    const FaceView& v = view.views_[i];
    if (v.face >= h->n_faces || !AllFinite(v.view_from_face, 4) || !AllFinite(v.centre_ab_mm, 2))
      return Corrupt("view", i);
  }
  for (uint32_t i = 0; i < h->n_features; ++i) {
    const FeatureRecord& f = view.features_[i];
    if (f.view >= h->n_views || f.level >= kMaxPyramidLevels || !std::isfinite(f.u_px) ||
        !std::isfinite(f.v_px) || !std::isfinite(f.angle_rad) || !std::isfinite(f.scale) ||
        !AllFinite(f.model_mm, 3))
      return Corrupt("feature", i);
  }
  // The kd-tree: children after their parent (so every descent ends), leaves inside the
  // descriptor array.
  for (uint32_t i = 0; i < h->n_nodes; ++i) {
    const KdNode& n = view.nodes_[i];
    if (n.leaf > 1) return Corrupt("kd-tree node kind", i);
    if (n.leaf) {
      if (n.second == 0 || n.first > h->n_features || n.second > h->n_features - n.first)
        return Corrupt("kd-tree leaf range", i);
    } else if (n.dim >= kDescriptorSize || !std::isfinite(n.split) || n.first <= i ||
               n.second <= i || n.first >= h->n_nodes || n.second >= h->n_nodes) {
      return Corrupt("kd-tree inner node", i);
    }
  }
  return view;
}

int FeatureDbView::FindModel(const char* name) const {
  for (uint32_t i = 0; i < model_count(); ++i) {
    if (std::strncmp(models_[i].name, name, kMaxModelNameLength + 1) == 0)
      return static_cast<int>(i);
  }
  return -1;
}

FaceTexels FeatureDbView::face_texels(uint32_t i) const {
  const TexturedFace& f = faces_[i];
  return {texels_ + f.texel_offset, f.texel_width, f.texel_height};
}

}  // namespace sh
