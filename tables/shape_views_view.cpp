#include "tables/shape_views_view.hpp"

#include <Eigen/Geometry>
#include <cmath>
#include <cstddef>
#include <cstring>

#include "recog/model/model_check.hpp"
#include "tables/blob_checks.hpp"

namespace sh {
namespace {

constexpr const char* kBlob = "view database";

Status Corrupt(const char* what) {
  return Status::Error(StatusCode::kDataLoss, "view database corrupt: %s", what);
}

bool AllFinite(const float* v, size_t n) {
  for (size_t i = 0; i < n; ++i) {
    if (!std::isfinite(v[i])) return false;
  }
  return true;
}

}  // namespace

Result<ShapeViewsView> ShapeViewsView::Open(const void* blob, size_t size) {
  SH_RETURN_IF_ERROR(CheckBlobHeader(
      blob, size,
      {"view database", kShapeViewsMagic, kShapeViewsVersion, sizeof(ShapeViewsHeader), 8}));
  const auto* bytes = static_cast<const uint8_t*>(blob);
  const auto* h = reinterpret_cast<const ShapeViewsHeader*>(bytes);
  if (h->reserved0 != 0 || !AllZero(h->reserved1, sizeof(h->reserved1))) {
    return Corrupt("reserved header bytes not zero");
  }
  if (h->window_side != kShapeViewWindowSide) {
    return Status::Error(StatusCode::kInvalidArgument,
                         "view database has %u-pixel windows, this build uses %d", h->window_side,
                         kShapeViewWindowSide);
  }
  if (h->n_models == 0 || h->n_models > kMaxShapeModels) {
    return Status::Error(StatusCode::kOutOfRange, "view database has %u models (1..%u supported)",
                         h->n_models, kMaxShapeModels);
  }
  if (h->n_views == 0 || h->n_views > kMaxShapeViews) {
    return Status::Error(StatusCode::kOutOfRange, "view database has %u views (1..%u supported)",
                         h->n_views, kMaxShapeViews);
  }
  if (h->n_components == 0 || h->n_components > kMaxShapeComponents ||
      h->component_stride != (h->n_components + 7) / 8 * 8) {
    return Status::Error(StatusCode::kOutOfRange,
                         "view database has %u components, stride %u (1..%u, stride rounded "
                         "up to 8)",
                         h->n_components, h->component_stride, kMaxShapeComponents);
  }
  if (!(std::isfinite(h->render_focal_px) && h->render_focal_px > 0) ||
      !(std::isfinite(h->render_distance_mm) && h->render_distance_mm > 0)) {
    return Corrupt("render camera");
  }
  // Sections follow each other in the order of the header, each at the next aligned offset:
  // any other offset is damage, even when it would still point inside the blob.
  {
    uint64_t at = AlignSection(sizeof(ShapeViewsHeader));
    for (const SectionRef* sec :
         {&h->models, &h->shape_models, &h->mean, &h->basis, &h->views, &h->coefficients}) {
      if (sec->offset != at) return Corrupt("sections out of order or not packed");
      at = AlignSection(sec->offset + sec->size);
    }
    if (at != h->total_size) return Corrupt("sections do not end at the blob's end");
  }
  const uint64_t total = h->total_size;
  SH_RETURN_IF_ERROR(CheckSection(h->models, h->n_models, sizeof(Model), total, kBlob, "model"));
  SH_RETURN_IF_ERROR(
      CheckSection(h->shape_models, h->n_models, sizeof(ShapeModelRecord), total, kBlob, "colour"));
  SH_RETURN_IF_ERROR(
      CheckSection(h->mean, kShapeViewWindowPixels, sizeof(float), total, kBlob, "mean"));
  SH_RETURN_IF_ERROR(CheckSection(h->basis, size_t{h->n_components} * kShapeViewWindowPixels,
                                  sizeof(QBasis::Raw), total, kBlob, "basis"));
  SH_RETURN_IF_ERROR(
      CheckSection(h->views, h->n_views, sizeof(ShapeViewRecord), total, kBlob, "view"));
  SH_RETURN_IF_ERROR(CheckSection(h->coefficients, size_t{h->n_views} * h->component_stride,
                                  sizeof(QCoefficient::Raw), total, kBlob, "coefficient"));

  ShapeViewsView v;
  v.header_ = h;
  v.models_ = reinterpret_cast<const Model*>(bytes + h->models.offset);
  v.shape_models_ = reinterpret_cast<const ShapeModelRecord*>(bytes + h->shape_models.offset);
  v.mean_ = reinterpret_cast<const float*>(bytes + h->mean.offset);
  v.basis_ = reinterpret_cast<const QBasis::Raw*>(bytes + h->basis.offset);
  v.views_ = reinterpret_cast<const ShapeViewRecord*>(bytes + h->views.offset);
  v.coefficients_ = reinterpret_cast<const QCoefficient::Raw*>(bytes + h->coefficients.offset);

  for (uint32_t i = 0; i < h->n_models; ++i) {
    const Model& m = v.models_[i];
    SH_RETURN_IF_ERROR(ValidateModelRecord(m, i, kBlob));
    const ShapeModelRecord& r = v.shape_models_[i];
    if (!AllFinite(r.kd, 3) || !(r.radius_mm > 0 && r.radius_mm < 1000) ||
        r.first_view > h->n_views || r.n_views > h->n_views - r.first_view) {
      return Status::Error(StatusCode::kDataLoss,
                           "view database corrupt: model '%s' colour, radius or view range",
                           m.name);
    }
    for (int k = 0; k < 3; ++k) {
      if (!(r.kd[k] >= 0 && r.kd[k] <= 1)) return Corrupt("colour outside 0..1");
    }
  }
  if (!AllFinite(v.mean_, kShapeViewWindowPixels)) return Corrupt("mean window not finite");
  for (uint32_t i = 0; i < h->n_views; ++i) {
    const ShapeViewRecord& r = v.views_[i];
    if (r.model >= h->n_models) return Corrupt("a view names a missing model");
    const ShapeModelRecord& m = v.shape_models_[r.model];
    if (i < m.first_view || i >= m.first_view + m.n_views) {
      return Corrupt("a view lies outside its model's view range");
    }
    double n2 = 0;
    for (int k = 0; k < 4; ++k) {
      const double q = QQuaternion::FromRaw(r.q[k]).ToDouble();
      n2 += q * q;
    }
    if (std::fabs(n2 - 1.0) > 1e-2) return Corrupt("a view orientation is not a unit quaternion");
  }
  return v;
}

int ShapeViewsView::FindModel(const char* name) const {
  for (uint32_t i = 0; i < model_count(); ++i) {
    if (std::strncmp(models_[i].name, name, kMaxModelNameLength + 1) == 0) return int(i);
  }
  return -1;
}

Eigen::Matrix3f ShapeViewsView::ViewRotation(uint32_t i) const {
  const ShapeViewRecord& r = views_[i];
  const Eigen::Quaternionf q(
      QQuaternion::FromRaw(r.q[0]).ToFloat(), QQuaternion::FromRaw(r.q[1]).ToFloat(),
      QQuaternion::FromRaw(r.q[2]).ToFloat(), QQuaternion::FromRaw(r.q[3]).ToFloat());
  return q.normalized().toRotationMatrix();
}

}  // namespace sh
