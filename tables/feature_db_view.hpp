// Read-only, validated, zero-copy access to a feature database blob (feature_db_format.hpp).
//
// Open() checks everything a corrupt, truncated or foreign blob could get wrong (sizes, CRC,
// every index, the kd-tree's structure, finite numbers) before any pointer into it is handed
// out; afterwards accessors are plain pointer arithmetic. The blob memory must outlive the view
// and be at least 16-byte aligned (mmap and linked-in data are 64-byte aligned).
#pragma once

#include <cstddef>
#include <cstdint>

#include "recog/base/status.hpp"
#include "tables/feature_db_format.hpp"
#include "tables/table_file.hpp"
#include "tables/texture_records.hpp"

namespace sh {

// A face's grey texture: row-major, `width` bytes a row.
struct FaceTexels {
  const uint8_t* texels = nullptr;
  int width = 0;
  int height = 0;
};

class FeatureDbView {
 public:
  FeatureDbView() = default;
  static Result<FeatureDbView> Open(const void* blob, size_t size);

  bool empty() const { return header_ == nullptr; }
  const FeatureDbHeader& header() const { return *header_; }

  uint32_t model_count() const { return header_->n_models; }
  const Model& model(uint32_t i) const { return models_[i]; }
  int FindModel(const char* name) const;  // index, or -1

  uint32_t face_count() const { return header_->n_faces; }
  const TexturedFace& face(uint32_t i) const { return faces_[i]; }
  // Grey texture of face i (texture_px_per_mm; see TexturedFace).
  FaceTexels face_texels(uint32_t i) const;

  uint32_t view_count() const { return header_->n_views; }
  const FaceView& view(uint32_t i) const { return views_[i]; }

  uint32_t feature_count() const { return header_->n_features; }
  const FeatureRecord& feature(uint32_t i) const { return features_[i]; }
  const TextureDescriptor& descriptor(uint32_t i) const { return descriptors_[i]; }

  KdTreeView tree() const { return {nodes_, header_->n_nodes, descriptors_, header_->n_features}; }

 private:
  const FeatureDbHeader* header_ = nullptr;
  const Model* models_ = nullptr;
  const TexturedFace* faces_ = nullptr;
  const FaceView* views_ = nullptr;
  const FeatureRecord* features_ = nullptr;
  const TextureDescriptor* descriptors_ = nullptr;
  const KdNode* nodes_ = nullptr;
  const uint8_t* texels_ = nullptr;
};

// A feature database file mapped read-only and validated in place (the tools and the firmware's
// `features` key).
class MappedFeatureDb : public MappedView<FeatureDbView> {
 public:
  MappedFeatureDb() : MappedView("feature database", SectionKind::kTextureFeatures) {}
};

}  // namespace sh
