#include "recog/shape/view_database.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstring>

#include "recog/base/blob_start.hpp"
#include "recog/base/crc32.hpp"
#include "recog/verify/visible_edges.hpp"

namespace sh {
namespace {

Status Corrupt(const char* what) {
  return Status::Error(StatusCode::kDataLoss, "view database corrupt: %s", what);
}

Status CheckSection(const ShapeSection& s, size_t count, size_t element_size, uint64_t total,
                    const char* name) {
  if (s.offset % kShapeSectionAlignment != 0) {
    return Status::Error(StatusCode::kDataLoss, "view database corrupt: %s section misaligned",
                         name);
  }
  if (s.offset > total || s.size > total - s.offset) {
    return Status::Error(StatusCode::kDataLoss,
                         "view database truncated: %s section ends past the blob", name);
  }
  if (s.size != count * element_size) {
    return Status::Error(StatusCode::kDataLoss,
                         "view database corrupt: %s section has %llu bytes, expected %zu", name,
                         static_cast<unsigned long long>(s.size), count * element_size);
  }
  return Status::Ok();
}

bool AllFinite(const float* v, size_t n) {
  for (size_t i = 0; i < n; ++i) {
    if (!std::isfinite(v[i])) return false;
  }
  return true;
}

// A k-best list kept sorted by distance (small k: insertion).
void Insert(Vector<ViewMatch>& best, size_t k, ViewMatch m) {
  if (best.size() == k && m.distance2 >= best.back().distance2) return;
  if (best.size() < k) {
    (void)best.push_back(m);
  } else {
    best.back() = m;
  }
  for (size_t i = best.size() - 1; i > 0 && best[i].distance2 < best[i - 1].distance2; --i) {
    std::swap(best[i], best[i - 1]);
  }
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
  if (h->window_side != kWindowSide) {
    return Status::Error(StatusCode::kInvalidArgument,
                         "view database has %u-pixel windows, this build uses %d", h->window_side,
                         kWindowSide);
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
    uint64_t at = AlignShapeSection(sizeof(ShapeViewsHeader));
    for (const ShapeSection* sec :
         {&h->models, &h->shape_models, &h->mean, &h->basis, &h->views, &h->coefficients}) {
      if (sec->offset != at) return Corrupt("sections out of order or not packed");
      at = AlignShapeSection(sec->offset + sec->size);
    }
    if (at != h->total_size) return Corrupt("sections do not end at the blob's end");
  }
  const uint64_t total = h->total_size;
  SH_RETURN_IF_ERROR(CheckSection(h->models, h->n_models, sizeof(Model), total, "model"));
  SH_RETURN_IF_ERROR(
      CheckSection(h->shape_models, h->n_models, sizeof(ShapeModelRecord), total, "colour"));
  SH_RETURN_IF_ERROR(CheckSection(h->mean, kWindowPixels, sizeof(float), total, "mean"));
  SH_RETURN_IF_ERROR(CheckSection(h->basis, size_t{h->n_components} * kWindowPixels,
                                  sizeof(QBasis::Raw), total, "basis"));
  SH_RETURN_IF_ERROR(CheckSection(h->views, h->n_views, sizeof(ShapeViewRecord), total, "view"));
  SH_RETURN_IF_ERROR(CheckSection(h->coefficients, size_t{h->n_views} * h->component_stride,
                                  sizeof(QCoefficient::Raw), total, "coefficient"));

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
    if (m.name[kMaxModelNameLength] != '\0' || m.name[0] == '\0') {
      return Corrupt("a model has no valid name");
    }
    if (!AllFinite(&m.corners_mm[0][0], 3 * static_cast<size_t>(kMaxModelCorners)) ||
        m.n_symmetries == 0 || m.n_symmetries > kMaxModelSymmetries) {
      return Status::Error(StatusCode::kDataLoss,
                           "view database corrupt: model '%s' has non-finite corners or no "
                           "symmetry group",
                           m.name);
    }
    const Status s = CheckModel(m);
    if (!s.ok()) return Status::Error(StatusCode::kDataLoss, "view database: %s", s.message());
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
  if (!AllFinite(v.mean_, kWindowPixels)) return Corrupt("mean window not finite");
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

namespace {

// Components of the blocks [first_block, end_block) of eight (the last block may be shorter).
void ProjectBlocks(const float* mean, const QBasis::Raw* basis, int n_components,
                   const ShapeWindow& window, int first_block, int end_block,
                   ShapeCoefficients* out) {
  float centred[kWindowPixels];
  for (int i = 0; i < kWindowPixels; ++i) centred[i] = window.v[i] - mean[i];
  // Each component's sum runs over the pixels in order, as one loop per component would; a few
  // components at once make independent sums the processor overlaps (and the compiler puts in
  // the lanes of one vector), the same values bit for bit.
  for (int k0 = first_block * kProjectBlock; k0 < std::min(n_components, end_block * kProjectBlock);
       k0 += kProjectBlock) {
    const int n = std::min(kProjectBlock, n_components - k0);
    const QBasis::Raw* b[kProjectBlock];
    for (int j = 0; j < kProjectBlock; ++j) {
      b[j] = basis + static_cast<size_t>(k0 + std::min(j, n - 1)) * kWindowPixels;
    }
    float sum[kProjectBlock] = {};
    for (int i = 0; i < kWindowPixels; ++i) {
      for (int j = 0; j < kProjectBlock; ++j) sum[j] += centred[i] * static_cast<float>(b[j][i]);
    }
    // Basis raw units -> value: divide by 2^14; value -> coefficient raw (saturating).
    for (int j = 0; j < n; ++j) {
      out->c[k0 + j] = QCoefficient::FromDouble(double(sum[j]) / QBasis::kScale).raw();
    }
  }
}

}  // namespace

void ProjectShapeWindow(const float* mean, const QBasis::Raw* basis, int n_components, int stride,
                        const ShapeWindow& window, ShapeCoefficients* out) {
  const int blocks = (n_components + kProjectBlock - 1) / kProjectBlock;
  ProjectBlocks(mean, basis, n_components, window, 0, blocks, out);
  for (int k = n_components; k < stride; ++k) out->c[k] = 0;
}

void ShapeViewsView::Project(const ShapeWindow& window, ShapeCoefficients* out) const {
  ProjectShapeWindow(mean_, basis_, header_->n_components, header_->component_stride, window, out);
}

void ShapeViewsView::ProjectShare(const ShapeWindow& window, int share, int shares,
                                  ShapeCoefficients* out) const {
  const int n_components = header_->n_components;
  const int blocks = (n_components + kProjectBlock - 1) / kProjectBlock;
  ProjectBlocks(mean_, basis_, n_components, window, blocks * share / shares,
                blocks * (share + 1) / shares, out);
  if (share + 1 == shares) {
    for (int k = n_components; k < header_->component_stride; ++k) out->c[k] = 0;
  }
}

void ShapeViewsView::Nearest(const ShapeCoefficients& query, uint32_t model_mask, size_t k,
                             Vector<ViewMatch>& out) const {
  out.clear();
  k = std::min(k, out.capacity());
  if (k == 0) return;
  const int stride = header_->component_stride;
  constexpr int kBlock = 16;  // components summed between early-exit checks
  // Views compared at once: independent sums the processor overlaps (the lanes of one vector),
  // each over the components in order, as one view at a time would sum them.
  constexpr uint32_t kTogether = 4;
  // Squared distances in raw units (2^-26 per unit^2); floats hold them to 24 bits, plenty for
  // ranking.
  float worst = std::numeric_limits<float>::infinity();
  for (uint32_t m = 0; m < header_->n_models; ++m) {
    if (!(model_mask & (1u << m))) continue;
    const ShapeModelRecord& rec = shape_models_[m];
    const uint32_t end_view = rec.first_view + rec.n_views;
    for (uint32_t v0 = rec.first_view; v0 < end_view; v0 += kTogether) {
      const uint32_t n = std::min(kTogether, end_view - v0);
      const QCoefficient::Raw* c[kTogether];
      for (uint32_t g = 0; g < kTogether; ++g) c[g] = coefficients(v0 + std::min(g, n - 1));
      float d2[kTogether] = {};
      // A sum that reaches the worst of a full list at a check cannot enter it: the views stop
      // once all of theirs have (a view that goes on is refused by Insert, as the list's worst
      // only falls).
      int i = 0;
      for (; i < stride; i += kBlock) {
        const int end = std::min(stride, i + kBlock);
        for (int j = i; j < end; ++j) {
          for (uint32_t g = 0; g < kTogether; ++g) {
            const float d = static_cast<float>(int32_t{query.c[j]} - int32_t{c[g][j]});
            d2[g] += d * d;
          }
        }
        bool all_out = true;
        for (uint32_t g = 0; g < n; ++g) all_out &= d2[g] >= worst;
        if (all_out) break;
      }
      if (i < stride) continue;
      for (uint32_t g = 0; g < n; ++g) {
        if (d2[g] >= worst) continue;
        Insert(out, k,
               {v0 + g, d2[g] / static_cast<float>(QCoefficient::kScale * QCoefficient::kScale)});
        if (out.size() == k) {
          worst = out.back().distance2 *
                  static_cast<float>(QCoefficient::kScale * QCoefficient::kScale);
        }
      }
    }
  }
}

Eigen::Matrix3f RayFrame(const Eigen::Vector3f& x_cam_mm) {
  const float n = x_cam_mm.norm();
  if (!(n > 0)) return Eigen::Matrix3f::Identity();
  return Eigen::Quaternionf::FromTwoVectors(Eigen::Vector3f::UnitZ(), x_cam_mm / n)
      .toRotationMatrix();
}

}  // namespace sh
