#include "tables/feature_db_view.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstring>

#include "recog/base/blob_start.hpp"
#include "recog/base/crc32.hpp"
#include "recog/model/model_check.hpp"

namespace sh {
namespace {

constexpr const char* kBlob = "feature database";

Status Corrupt(const char* what, uint32_t index) {
  return Status::Error(StatusCode::kDataLoss, "feature database corrupt: %s %u", what, index);
}

Status CheckSection(const SectionRef& s, uint64_t count, size_t element_size, uint64_t total,
                    const char* name) {
  if (s.offset % kSectionAlignment != 0) {
    return Status::Error(StatusCode::kDataLoss, "feature database corrupt: %s section misaligned",
                         name);
  }
  if (s.offset > total || s.size > total - s.offset) {
    return Status::Error(StatusCode::kDataLoss,
                         "feature database truncated: %s section ends past the blob", name);
  }
  const uint64_t expected = count * uint64_t{element_size};
  if (s.size != expected) {
    return Status::Error(
        StatusCode::kDataLoss, "feature database corrupt: %s section has %llu bytes, expected %llu",
        name, static_cast<unsigned long long>(s.size), static_cast<unsigned long long>(expected));
  }
  return Status::Ok();
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

}  // namespace

Result<FeatureDbView> FeatureDbView::Open(const void* blob, size_t size) {
  SH_RETURN_IF_ERROR(CheckBlobHeader(
      blob, size, {kBlob, kFeatureDbMagic, kFeatureDbFormatVersion, sizeof(FeatureDbHeader), 16}));
  const auto* bytes = static_cast<const uint8_t*>(blob);
  const auto* h = reinterpret_cast<const FeatureDbHeader*>(bytes);
  if (h->descriptor_size != texture::kDescriptorSize) {
    return Status::Error(StatusCode::kDataLoss, "%s corrupt: descriptor size %u, this build's %d",
                         kBlob, h->descriptor_size, texture::kDescriptorSize);
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
  const Status extraction = ExtractionConfig(h->extraction).Validate();
  if (!extraction.ok()) {
    return Status::Error(StatusCode::kDataLoss, "%s corrupt: extraction settings: %s", kBlob,
                         extraction.message());
  }
  const uint64_t total = h->total_size;
  SH_RETURN_IF_ERROR(CheckSection(h->models, h->n_models, sizeof(Model), total, "model"));
  SH_RETURN_IF_ERROR(CheckSection(h->faces, h->n_faces, sizeof(TexturedFace), total, "face"));
  SH_RETURN_IF_ERROR(CheckSection(h->views, h->n_views, sizeof(FaceView), total, "view"));
  SH_RETURN_IF_ERROR(
      CheckSection(h->features, h->n_features, sizeof(FeatureRecord), total, "feature"));
  SH_RETURN_IF_ERROR(CheckSection(h->descriptors, h->n_features, sizeof(texture::TextureDescriptor),
                                  total, "descriptor"));
  SH_RETURN_IF_ERROR(CheckSection(h->nodes, h->n_nodes, sizeof(texture::KdNode), total, "node"));
  SH_RETURN_IF_ERROR(CheckSection(h->texels, h->n_texel_bytes, 1, total, "texel"));

  FeatureDbView view;
  view.header_ = h;
  view.models_ = reinterpret_cast<const Model*>(bytes + h->models.offset);
  view.faces_ = reinterpret_cast<const TexturedFace*>(bytes + h->faces.offset);
  view.views_ = reinterpret_cast<const FaceView*>(bytes + h->views.offset);
  view.features_ = reinterpret_cast<const FeatureRecord*>(bytes + h->features.offset);
  view.descriptors_ =
      reinterpret_cast<const texture::TextureDescriptor*>(bytes + h->descriptors.offset);
  view.nodes_ = reinterpret_cast<const texture::KdNode*>(bytes + h->nodes.offset);
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
    if (f.view >= h->n_views || f.level >= texture::kMaxPyramidLevels || !std::isfinite(f.u_px) ||
        !std::isfinite(f.v_px) || !std::isfinite(f.angle_rad) || !std::isfinite(f.scale) ||
        !AllFinite(f.model_mm, 3))
      return Corrupt("feature", i);
  }
  // The kd-tree: children after their parent (so every descent ends), leaves inside the
  // descriptor array.
  for (uint32_t i = 0; i < h->n_nodes; ++i) {
    const texture::KdNode& n = view.nodes_[i];
    if (n.leaf > 1) return Corrupt("kd-tree node kind", i);
    if (n.leaf) {
      if (n.second == 0 || n.first > h->n_features || n.second > h->n_features - n.first)
        return Corrupt("kd-tree leaf range", i);
    } else if (n.dim >= texture::kDescriptorSize || !std::isfinite(n.split) || n.first <= i ||
               n.second <= i || n.first >= h->n_nodes || n.second >= h->n_nodes) {
      return Corrupt("kd-tree inner node", i);
    }
  }
  return view;
}

texture::TextureFeatureConfig ExtractionConfig(const FeatureDbExtraction& e) {
  texture::TextureFeatureConfig c;
  c.levels = static_cast<int>(std::min<uint32_t>(e.levels, 1000));
  c.input_sigma_px = e.input_sigma_px;
  c.level_sigma_px = e.level_sigma_px;
  c.integration_sigma_px = e.integration_sigma_px;
  c.harris_k = e.harris_k;
  c.min_response = e.min_response;
  c.nms_radius_px = static_cast<int>(std::min<uint32_t>(e.nms_radius_px, 1000));
  c.orientation.sigma_px = e.orientation_sigma_px;
  c.orientation.secondary_ratio = e.secondary_orientation_ratio;
  c.orientation.max_orientations = static_cast<int>(std::min<uint32_t>(e.max_orientations, 1000));
  return c;
}

FeatureDbExtraction ExtractionRecord(const texture::TextureFeatureConfig& c) {
  FeatureDbExtraction e{};
  e.levels = static_cast<uint32_t>(c.levels);
  e.input_sigma_px = c.input_sigma_px;
  e.level_sigma_px = c.level_sigma_px;
  e.integration_sigma_px = c.integration_sigma_px;
  e.harris_k = c.harris_k;
  e.min_response = c.min_response;
  e.nms_radius_px = static_cast<uint32_t>(c.nms_radius_px);
  e.orientation_sigma_px = c.orientation.sigma_px;
  e.secondary_orientation_ratio = c.orientation.secondary_ratio;
  e.max_orientations = static_cast<uint32_t>(c.orientation.max_orientations);
  return e;
}

int FeatureDbView::FindModel(const char* name) const {
  for (uint32_t i = 0; i < model_count(); ++i) {
    if (std::strncmp(models_[i].name, name, kMaxModelNameLength + 1) == 0)
      return static_cast<int>(i);
  }
  return -1;
}

ConstGrayView FeatureDbView::face_texture(uint32_t i) const {
  const TexturedFace& f = faces_[i];
  return {texels_ + f.texel_offset, f.texel_width, f.texel_height, f.texel_width};
}

}  // namespace sh
