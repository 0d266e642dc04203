#include "tools/tablegen/feature_db_builder.hpp"

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstring>
#include <memory>
#include <numeric>

#include "recog/base/crc32.hpp"
#include "recog/image/gaussian.hpp"
#include "recog/texture/descriptor.hpp"
#include "recog/texture/float_planes.hpp"
#include "recog/texture/polygon.hpp"
#include "tables/feature_db_format.hpp"
#include "tables/feature_db_view.hpp"
#include "tools/tablegen/blob_writer.hpp"
#include "tools/tablegen/kd_tree_builder.hpp"

namespace sh {
namespace {

using texture::FloatView;
using texture::TextureDescriptor;

struct FloatImage {
  int width = 0, height = 0;
  std::vector<float> pixels;
  FloatImage() = default;
  FloatImage(int w, int h, float fill = 0.0f)
      : width(w), height(h), pixels(static_cast<size_t>(w) * h, fill) {}
  FloatView view() { return {pixels.data(), width, height, width}; }
  texture::ConstFloatView view() const { return {pixels.data(), width, height, width}; }
};

// Gaussian blur of a float image (no-op below the smallest kernel).
Status Blur(FloatImage& image, float sigma_px) {
  if (sigma_px < kMinGaussianSigmaPx) return Status::Ok();
  GaussianKernel k;
  SH_RETURN_IF_ERROR(MakeGaussianKernel(std::min(sigma_px, kMaxGaussianSigmaPx), 0, k));
  FloatImage tmp(image.width, image.height);
  texture::BlurPlane(image.view(), k, tmp.view(), image.view());
  return Status::Ok();
}

// Face frame and polygon (feature_db_format.hpp, TexturedFace).
TexturedFace FaceGeometry(const Model& m, int model_index, int f) {
  const ModelFace& face = m.faces[f];
  TexturedFace out{};
  out.model = static_cast<uint16_t>(model_index);
  out.model_face = static_cast<uint8_t>(f);
  out.n_corners = face.n_vertices;
  const Eigen::Vector3f o = m.corner(face.vertices[0]);
  const Eigen::Vector3f a = (m.corner(face.vertices[1]) - o).normalized();
  const Eigen::Vector3f b = m.face_normal(f).cross(a).normalized();
  for (int k = 0; k < 3; ++k) {
    out.origin_mm[k] = o[k];
    out.axis_a[k] = a[k];
    out.axis_b[k] = b[k];
  }
  out.min_ab_mm[0] = out.min_ab_mm[1] = 1e30f;
  out.max_ab_mm[0] = out.max_ab_mm[1] = -1e30f;
  for (int k = 0; k < face.n_vertices; ++k) {
    const Eigen::Vector3f d = m.corner(face.vertices[k]) - o;
    const float ab[2] = {d.dot(a), d.dot(b)};
    for (int c = 0; c < 2; ++c) {
      out.corners_ab_mm[k][c] = ab[c];
      out.min_ab_mm[c] = std::min(out.min_ab_mm[c], ab[c]);
      out.max_ab_mm[c] = std::max(out.max_ab_mm[c], ab[c]);
    }
  }
  return out;
}

Eigen::Vector3f FacePoint(const TexturedFace& f, float a, float b) {
  return Eigen::Vector3f(f.origin_mm[0], f.origin_mm[1], f.origin_mm[2]) +
         a * Eigen::Vector3f(f.axis_a[0], f.axis_a[1], f.axis_a[2]) +
         b * Eigen::Vector3f(f.axis_b[0], f.axis_b[1], f.axis_b[2]);
}

// The face's texture rectified at `ppm` with `margin` texels around the face's bounding box
// (texel (i, j) centre at a = min_a + (i - margin + 0.5) / ppm, b = max_b - (j - margin + 0.5) /
// ppm), sampled bilinearly from the texture image (already blurred for this resolution); texels
// outside the polygon (the margin among them) get the mean of those inside.
FloatImage RectifyFace(const TexturedFace& face, const FaceTextureMap& map,
                       const FloatImage& texture, float ppm, int margin) {
  const int w =
      std::max(1, static_cast<int>(std::lround((face.max_ab_mm[0] - face.min_ab_mm[0]) * ppm))) +
      2 * margin;
  const int h =
      std::max(1, static_cast<int>(std::lround((face.max_ab_mm[1] - face.min_ab_mm[1]) * ppm))) +
      2 * margin;
  FloatImage out(w, h);
  std::vector<uint8_t> inside(static_cast<size_t>(w) * h, 0);
  Eigen::Vector2f poly[kMaxTexturedFaceCorners];
  for (int k = 0; k < face.n_corners; ++k)
    poly[k] = {face.corners_ab_mm[k][0], face.corners_ab_mm[k][1]};
  double sum = 0.0;
  size_t n_inside = 0;
  for (int j = 0; j < h; ++j) {
    for (int i = 0; i < w; ++i) {
      const float a = face.min_ab_mm[0] + (static_cast<float>(i - margin) + 0.5f) / ppm;
      const float b = face.max_ab_mm[1] - (static_cast<float>(j - margin) + 0.5f) / ppm;
      const Eigen::Vector3f x = FacePoint(face, a, b);
      float uv[2];
      FaceUv(map, x.data(), uv);
      // Texture coordinates to texture pixels (pixel centres at integers, row 0 at v = 1).
      const float tx = uv[0] * texture.width - 0.5f;
      const float ty = (1.0f - uv[1]) * texture.height - 0.5f;
      const size_t k = static_cast<size_t>(j) * w + i;
      out.pixels[k] = texture::SampleBilinear(texture.view(), tx, ty);
      if (texture::InsideDistance(poly, face.n_corners, {a, b}) > -0.5f / ppm) {
        inside[k] = 1;
        sum += out.pixels[k];
        ++n_inside;
      }
    }
  }
  const float mean = n_inside > 0 ? static_cast<float>(sum / n_inside) : 0.5f;
  for (size_t k = 0; k < inside.size(); ++k) {
    if (!inside[k]) out.pixels[k] = mean;
  }
  return out;
}

// Texels per millimetre of the texture image along the face (the larger of the two axes).
float TextureDensity(const TexturedFace& face, const FaceTextureMap& map, const FloatImage& tex) {
  float uv0[2], uva[2], uvb[2];
  const Eigen::Vector3f x0 = FacePoint(face, 0, 0), xa = FacePoint(face, 1, 0),
                        xb = FacePoint(face, 0, 1);
  FaceUv(map, x0.data(), uv0);
  FaceUv(map, xa.data(), uva);
  FaceUv(map, xb.data(), uvb);
  const float da = std::hypot((uva[0] - uv0[0]) * tex.width, (uva[1] - uv0[1]) * tex.height);
  const float db = std::hypot((uvb[0] - uv0[0]) * tex.width, (uvb[1] - uv0[1]) * tex.height);
  return std::max(da, db);
}

// Blur that takes a texture of `density` texels per mm down to `ppm` without aliasing (the
// image is assumed sharp: 0.5 texel of blur).
float AntiAliasSigma(float density, float ppm) {
  const float ratio = density / ppm;
  return ratio > 1.0f ? 0.5f * std::sqrt(ratio * ratio - 1.0f) : 0.0f;
}

std::vector<uint8_t> ToBytes(const FloatImage& image) {
  std::vector<uint8_t> out(image.pixels.size());
  for (size_t i = 0; i < out.size(); ++i) {
    out[i] = static_cast<uint8_t>(std::clamp(image.pixels[i] * 255.0f + 0.5f, 0.0f, 255.0f));
  }
  return out;
}

struct LearntFeature {
  FeatureRecord record{};
  TextureDescriptor descriptor;
};

// A view of the rectified face (tilt 0: the rectified image itself). `view_from_rect` acts on
// rectified pixel offsets from the image centre.
struct ViewImage {
  FloatImage image;
  Eigen::Matrix2f view_from_rect = Eigen::Matrix2f::Identity();
  Eigen::Vector2f rect_centre = Eigen::Vector2f::Zero();
  Eigen::Vector2f view_centre = Eigen::Vector2f::Zero();
};

Result<ViewImage> TiltedView(const FloatImage& rect, float tilt, float phi_rad) {
  ViewImage v;
  const Eigen::Rotation2Df r(phi_rad);
  const Eigen::Matrix2f rot = r.toRotationMatrix();
  v.view_from_rect = rot * Eigen::Vector2f(1.0f, 1.0f / tilt).asDiagonal() * rot.transpose();
  v.rect_centre = {0.5f * (rect.width - 1), 0.5f * (rect.height - 1)};
  Eigen::Vector2f lo(1e30f, 1e30f), hi(-1e30f, -1e30f);
  for (float cx : {-0.5f, rect.width - 0.5f}) {
    for (float cy : {-0.5f, rect.height - 0.5f}) {
      const Eigen::Vector2f p = v.view_from_rect * (Eigen::Vector2f(cx, cy) - v.rect_centre);
      lo = lo.cwiseMin(p);
      hi = hi.cwiseMax(p);
    }
  }
  const int w = static_cast<int>(std::ceil(hi.x() - lo.x()));
  const int h = static_cast<int>(std::ceil(hi.y() - lo.y()));
  if (w > kMaxImageWidth || h > kMaxImageHeight) {
    return Status::Error(StatusCode::kOutOfRange, "tilted view %dx%d larger than %dx%d", w, h,
                         kMaxImageWidth, kMaxImageHeight);
  }
  v.view_centre = {0.5f * (w - 1), 0.5f * (h - 1)};
  // Anti-aliasing for the compression by 1 / tilt (isotropic: slightly more than needed across
  // the tilt direction), as ASIFT does.
  FloatImage src = rect;
  SH_RETURN_IF_ERROR(Blur(src, 0.8f * std::sqrt(tilt * tilt - 1.0f)));
  double sum = 0.0;
  for (float p : rect.pixels) sum += p;
  const float mean = static_cast<float>(sum / static_cast<double>(rect.pixels.size()));
  v.image = FloatImage(w, h, mean);
  const Eigen::Matrix2f rect_from_view = v.view_from_rect.inverse();
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const Eigen::Vector2f p =
          rect_from_view *
              (Eigen::Vector2f(static_cast<float>(x), static_cast<float>(y)) - v.view_centre) +
          v.rect_centre;
      if (p.x() < -0.5f || p.y() < -0.5f || p.x() > rect.width - 0.5f || p.y() > rect.height - 0.5f)
        continue;
      v.image.pixels[static_cast<size_t>(y) * w + x] =
          texture::SampleBilinear(src.view(), p.x(), p.y());
    }
  }
  return v;
}

}  // namespace

int ViewMarginPx(const FeatureDbBuildOptions& options) {
  // A keypoint of level k lies at least DescriptorBorderPx() level pixels inside its image, and
  // is kept at least half that (0.5 * border * scale) inside the face: a margin of half the
  // border at the coarsest level's scale, stretched by the largest tilt, lets every kept
  // position be detected.
  const float coarsest_scale =
      std::pow(1.0f / texture::kPyramidStep, static_cast<float>(options.features.levels - 1));
  float max_tilt = 1.0f;
  for (float t : options.tilts) max_tilt = std::max(max_tilt, t);
  return static_cast<int>(std::ceil(0.5f * static_cast<float>(texture::DescriptorBorderPx()) *
                                    coarsest_scale * max_tilt)) +
         1;
}

bool LearningView::Inside(const Eigen::Vector2f& p, float margin_px) const {
  return texture::InsideDistance(polygon_px, n_polygon, p) >= margin_px;
}

Eigen::Vector3f LearningView::ModelPoint(const TexturedFace& face, const Eigen::Vector2f& p) const {
  const Eigen::Vector2f ab = centre_ab_mm + view_from_face.inverse() * (p - view_of_centre);
  return FacePoint(face, ab.x(), ab.y());
}

Result<FaceLearning> LearnFace(const TexturedModel& tm, int fi,
                               const FeatureDbBuildOptions& options) {
  const FaceTextureMap& map = tm.texturing.faces[fi];
  if (fi < 0 || fi >= tm.model.n_faces || map.material < 0 ||
      static_cast<size_t>(map.material) >= tm.textures.size() ||
      tm.textures[static_cast<size_t>(map.material)].pixels.empty()) {
    return Status::Error(StatusCode::kInvalidArgument,
                         "feature database: face %d of '%s' is not printed", fi, tm.model.name);
  }
  if (tm.model.faces[fi].n_vertices > kMaxTexturedFaceCorners) {
    return Status::Error(StatusCode::kOutOfRange,
                         "feature database: printed face %d of '%s' has %d corners (at most %d)",
                         fi, tm.model.name, tm.model.faces[fi].n_vertices, kMaxTexturedFaceCorners);
  }
  const float ppm = options.feature_px_per_mm;
  const int margin = ViewMarginPx(options);
  FaceLearning out;
  out.face = FaceGeometry(tm.model, 0, fi);
  const TexturedFace& face = out.face;
  // The texture image as a float plane on [0, 1].
  const GreyImage& g = tm.textures[static_cast<size_t>(map.material)];
  FloatImage tex(g.width, g.height);
  for (size_t i = 0; i < g.pixels.size(); ++i) tex.pixels[i] = g.pixels[i] / 255.0f;
  const float density = TextureDensity(face, map, tex);
  const float width_mm = face.max_ab_mm[0] - face.min_ab_mm[0];
  const float height_mm = face.max_ab_mm[1] - face.min_ab_mm[1];
  if (width_mm * ppm + 2 * margin > kMaxImageWidth ||
      height_mm * ppm + 2 * margin > kMaxImageHeight ||
      width_mm * options.texture_px_per_mm > kMaxFaceTextureSide ||
      height_mm * options.texture_px_per_mm > kMaxFaceTextureSide) {
    return Status::Error(StatusCode::kOutOfRange,
                         "feature database: face %d of '%s' (%.0f x %.0f mm) is too large at "
                         "%.1f px/mm; lower the resolution",
                         fi, tm.model.name, static_cast<double>(width_mm),
                         static_cast<double>(height_mm), static_cast<double>(ppm));
  }
  // Verification texture.
  FloatImage blurred = tex;
  SH_RETURN_IF_ERROR(Blur(blurred, AntiAliasSigma(density, options.texture_px_per_mm)));
  const FloatImage small = RectifyFace(face, map, blurred, options.texture_px_per_mm, 0);
  out.face.texel_width = static_cast<uint16_t>(small.width);
  out.face.texel_height = static_cast<uint16_t>(small.height);
  out.texture.width = small.width;
  out.texture.height = small.height;
  out.texture.pixels = ToBytes(small);
  // The views.
  blurred = tex;
  SH_RETURN_IF_ERROR(Blur(blurred, AntiAliasSigma(density, ppm)));
  const FloatImage rect = RectifyFace(face, map, blurred, ppm, margin);
  const Eigen::Vector2f centre_ab(0.5f * (face.min_ab_mm[0] + face.max_ab_mm[0]),
                                  0.5f * (face.min_ab_mm[1] + face.max_ab_mm[1]));
  // Rectified pixels per millimetre offset from the centre: a right, b up (rows down).
  const Eigen::Matrix2f rect_from_face = Eigen::Vector2f(ppm, -ppm).asDiagonal();
  for (int t = 0; t <= static_cast<int>(options.tilts.size()); ++t) {
    const int directions = t == 0 ? 1 : options.tilt_directions;
    for (int d = 0; d < directions; ++d) {
      ViewImage view;
      if (t == 0) {
        view.image = rect;
        view.rect_centre = view.view_centre = {0.5f * (rect.width - 1), 0.5f * (rect.height - 1)};
      } else {
        const float phi = 3.14159265f * static_cast<float>(d) / static_cast<float>(directions);
        Result<ViewImage> v = TiltedView(rect, options.tilts[static_cast<size_t>(t - 1)], phi);
        if (!v.ok()) return v.status();
        view = std::move(*v);
      }
      LearningView lv;
      lv.tilt = t;
      // Face millimetres (from the centre) to view pixels (from the face centre's image). The
      // rectified image centre is the face centre: the rectified image spans the face's
      // bounding box exactly (up to rounding of its size, corrected here).
      const Eigen::Vector2f rect_centre_of_face(
          (centre_ab.x() - face.min_ab_mm[0]) * ppm - 0.5f + static_cast<float>(margin),
          (face.max_ab_mm[1] - centre_ab.y()) * ppm - 0.5f + static_cast<float>(margin));
      lv.view_from_face = view.view_from_rect * rect_from_face;
      lv.view_of_centre =
          view.view_from_rect * (rect_centre_of_face - view.rect_centre) + view.view_centre;
      lv.centre_ab_mm = centre_ab;
      lv.n_polygon = face.n_corners;
      for (int k = 0; k < face.n_corners; ++k) {
        lv.polygon_px[k] =
            lv.view_from_face *
                (Eigen::Vector2f(face.corners_ab_mm[k][0], face.corners_ab_mm[k][1]) - centre_ab) +
            lv.view_of_centre;
      }
      lv.image.width = view.image.width;
      lv.image.height = view.image.height;
      lv.image.pixels = ToBytes(view.image);
      out.views.push_back(std::move(lv));
    }
  }
  return out;
}

namespace {

// The models and options BuildFeatureDb accepts.
Status CheckFeatureDbOptions(const std::vector<TexturedModel>& models,
                             const FeatureDbBuildOptions& options) {
  SH_RETURN_IF_ERROR(options.features.Validate());
  if (models.empty() || models.size() > kMaxFeatureDbModels) {
    return Status::Error(StatusCode::kOutOfRange, "feature database: %zu models (1..%u)",
                         models.size(), kMaxFeatureDbModels);
  }
  if (!(options.feature_px_per_mm > 0.0f && options.feature_px_per_mm <= 50.0f) ||
      !(options.texture_px_per_mm > 0.0f && options.texture_px_per_mm <= 50.0f)) {
    return Status::Error(StatusCode::kOutOfRange,
                         "feature database: resolutions must be in (0, 50] px/mm");
  }
  for (float t : options.tilts) {
    if (!(t > 1.0f && t <= 4.0f)) {
      return Status::Error(StatusCode::kOutOfRange,
                           "feature database: tilt %.2f not in (1, 4] (1 / cos of the angle)",
                           static_cast<double>(t));
    }
  }
  if (options.tilt_directions < 1 || options.tilt_directions > 16 || options.leaf_size < 1 ||
      options.leaf_size > 256) {
    return Status::Error(StatusCode::kOutOfRange,
                         "feature database: 1..16 tilt directions and leaf size 1..256 required");
  }
  return Status::Ok();
}

// The database's contents as learnt, features in the order found.
struct LearntDb {
  std::vector<Model> models;
  std::vector<TexturedFace> faces;
  std::vector<FaceView> views;
  std::vector<LearntFeature> features;
  std::vector<uint8_t> texels;
};

// Learns the printed faces of models, one after the other, into a LearntDb (one extractor and
// its output for all views).
class FeatureLearner {
 public:
  // Model `mi`'s printed faces; a model without features is refused.
  Status AddModel(const TexturedModel& tm, size_t mi, const FeatureDbBuildOptions& options,
                  LearntDb* db, FeatureDbBuildReport* rep) {
    if (!tm.texturing.textured()) {
      return Status::Error(StatusCode::kInvalidArgument,
                           "feature database: model '%s' has no printed face", tm.model.name);
    }
    db->models.push_back(tm.model);
    const size_t first_feature = db->features.size();
    for (int fi = 0; fi < tm.model.n_faces; ++fi) {
      if (tm.texturing.faces[fi].material < 0) continue;
      SH_RETURN_IF_ERROR(AddFace(tm, mi, fi, options, db, rep));
    }
    // A carton without features is never found: refused when built, not written to fail later.
    if (db->features.size() == first_feature) {
      return Status::Error(StatusCode::kInvalidArgument,
                           "feature database: model '%s' gives no features: its print is too "
                           "small or too flat (1 x 1, one grey level)",
                           tm.model.name);
    }
    return Status::Ok();
  }

 private:
  // Printed face fi of model mi: its verification texture, its views and their features.
  Status AddFace(const TexturedModel& tm, size_t mi, int fi, const FeatureDbBuildOptions& options,
                 LearntDb* db, FeatureDbBuildReport* rep) {
    if (db->faces.size() >= kMaxFeatureDbFaces) {
      return Status::Error(StatusCode::kResourceExhausted,
                           "feature database: more than %u printed faces", kMaxFeatureDbFaces);
    }
    Result<FaceLearning> learning = LearnFace(tm, fi, options);
    if (!learning.ok()) return learning.status();
    TexturedFace face = learning->face;
    face.model = static_cast<uint16_t>(mi);
    face.texel_offset = db->texels.size();
    db->texels.insert(db->texels.end(), learning->texture.pixels.begin(),
                      learning->texture.pixels.end());
    const uint32_t face_index = static_cast<uint32_t>(db->faces.size());
    uint32_t face_features = 0;
    for (const LearningView& view : learning->views) {
      if (db->views.size() >= kMaxFeatureDbViews) {
        return Status::Error(StatusCode::kResourceExhausted, "feature database: more than %u views",
                             kMaxFeatureDbViews);
      }
      FaceView fv{};
      fv.face = static_cast<uint16_t>(face_index);
      fv.tilt = static_cast<uint8_t>(view.tilt);
      fv.view_from_face[0] = view.view_from_face(0, 0);
      fv.view_from_face[1] = view.view_from_face(0, 1);
      fv.view_from_face[2] = view.view_from_face(1, 0);
      fv.view_from_face[3] = view.view_from_face(1, 1);
      fv.centre_ab_mm[0] = view.centre_ab_mm.x();
      fv.centre_ab_mm[1] = view.centre_ab_mm.y();
      const uint32_t view_index = static_cast<uint32_t>(db->views.size());
      db->views.push_back(fv);
      SH_RETURN_IF_ERROR(AddViewFeatures(view, learning->face, view_index, options, &db->features,
                                         &face_features));
    }
    face.n_features = face_features;
    db->faces.push_back(face);
    rep->faces.push_back({tm.model.name, fi, face.texel_width, face.texel_height, face_features});
    return Status::Ok();
  }

  // The features of one view (view_index) of `face` that lie inside the face far enough for
  // their descriptor window, appended to `learnt` and counted in face_features.
  Status AddViewFeatures(const LearningView& view, const TexturedFace& face, uint32_t view_index,
                         const FeatureDbBuildOptions& options, std::vector<LearntFeature>* learnt,
                         uint32_t* face_features) {
    SH_RETURN_IF_ERROR(extractor_->Extract(view.image.view(), options.features, features_.get()));
    for (size_t k = 0; k < features_->keypoints.size(); ++k) {
      const texture::TextureKeypoint& kp = features_->keypoints[k];
      const Eigen::Vector2f p(kp.x_px, kp.y_px);
      const float window = 0.5f * static_cast<float>(texture::DescriptorBorderPx()) * kp.scale;
      if (!view.Inside(p, window)) continue;
      if (learnt->size() >= kMaxFeatureDbFeatures) {
        return Status::Error(StatusCode::kResourceExhausted,
                             "feature database: more than %u features", kMaxFeatureDbFeatures);
      }
      const Eigen::Vector2f uv = p - view.view_of_centre;
      const Eigen::Vector3f x = view.ModelPoint(face, p);
      LearntFeature lf;
      lf.record.u_px = uv.x();
      lf.record.v_px = uv.y();
      lf.record.angle_rad = kp.angle_rad;
      lf.record.scale = kp.scale;
      for (int c = 0; c < 3; ++c) lf.record.model_mm[c] = x[c];
      lf.record.view = static_cast<uint16_t>(view_index);
      lf.record.level = kp.level;
      lf.descriptor = features_->descriptors[k];
      learnt->push_back(lf);
      ++*face_features;
    }
    return Status::Ok();
  }

  std::unique_ptr<texture::TextureFeatureExtractor> extractor_ =
      std::make_unique<texture::TextureFeatureExtractor>();
  std::unique_ptr<texture::TextureFeatures> features_ =
      std::make_unique<texture::TextureFeatures>();
};

// The features in the kd-tree's leaf order, and the tree.
struct OrderedFeatures {
  std::vector<FeatureRecord> records;
  std::vector<TextureDescriptor> descriptors;
  std::vector<texture::KdNode> nodes;
};

OrderedFeatures OrderByKdTree(const std::vector<LearntFeature>& learnt, uint32_t leaf_size,
                              uint32_t* tree_depth) {
  std::vector<TextureDescriptor> unordered(learnt.size());
  for (size_t i = 0; i < learnt.size(); ++i) unordered[i] = learnt[i].descriptor;
  std::vector<uint32_t> order;
  OrderedFeatures out;
  BuildKdTree(unordered, leaf_size, &out.nodes, &order, tree_depth);
  out.records.resize(learnt.size());
  out.descriptors.resize(learnt.size());
  for (size_t i = 0; i < order.size(); ++i) {
    out.records[i] = learnt[order[i]].record;
    out.descriptors[i] = learnt[order[i]].descriptor;
  }
  return out;
}

// The blob (feature_db_format.hpp): header, sections, CRC.
std::vector<uint8_t> WriteFeatureDb(const LearntDb& db, const OrderedFeatures& ordered,
                                    const FeatureDbBuildOptions& options) {
  const std::vector<Model>& db_models = db.models;
  const std::vector<TexturedFace>& faces = db.faces;
  const std::vector<FaceView>& views = db.views;
  const std::vector<uint8_t>& texels = db.texels;
  const std::vector<FeatureRecord>& records = ordered.records;
  const std::vector<TextureDescriptor>& descriptors = ordered.descriptors;
  const std::vector<texture::KdNode>& nodes = ordered.nodes;
  FeatureDbHeader h{};
  std::memcpy(h.magic, kFeatureDbMagic, sizeof(kFeatureDbMagic));
  h.format_version = kFeatureDbFormatVersion;
  h.descriptor_size = texture::kDescriptorSize;
  h.header_size = sizeof(FeatureDbHeader);
  h.n_models = static_cast<uint32_t>(db_models.size());
  h.n_faces = static_cast<uint32_t>(faces.size());
  h.n_views = static_cast<uint32_t>(views.size());
  h.n_features = static_cast<uint32_t>(records.size());
  h.n_nodes = static_cast<uint32_t>(nodes.size());
  h.n_texel_bytes = texels.size();
  h.feature_px_per_mm = options.feature_px_per_mm;
  h.texture_px_per_mm = options.texture_px_per_mm;
  h.extraction = ExtractionRecord(options.features);
  SectionLayout layout(sizeof(FeatureDbHeader));
  layout.Place(&h.models, db_models.size() * sizeof(Model));
  layout.Place(&h.faces, faces.size() * sizeof(TexturedFace));
  layout.Place(&h.views, views.size() * sizeof(FaceView));
  layout.Place(&h.features, records.size() * sizeof(FeatureRecord));
  layout.Place(&h.descriptors, descriptors.size() * sizeof(TextureDescriptor));
  layout.Place(&h.nodes, nodes.size() * sizeof(texture::KdNode));
  layout.Place(&h.texels, texels.size());
  h.total_size = layout.total_size();
  std::vector<uint8_t> blob(layout.total_size(), 0);
  PutSection(blob, h.models, db_models.data(), db_models.size());
  PutSection(blob, h.faces, faces.data(), faces.size());
  PutSection(blob, h.views, views.data(), views.size());
  PutSection(blob, h.features, records.data(), records.size());
  PutSection(blob, h.descriptors, descriptors.data(), descriptors.size());
  PutSection(blob, h.nodes, nodes.data(), nodes.size());
  PutSection(blob, h.texels, texels.data(), texels.size());
  SealBlob(blob, h);
  return blob;
}

}  // namespace

Result<std::vector<uint8_t>> BuildFeatureDb(const std::vector<TexturedModel>& models,
                                            const FeatureDbBuildOptions& options,
                                            FeatureDbBuildReport* report) {
  SH_RETURN_IF_ERROR(CheckFeatureDbOptions(models, options));
  FeatureDbBuildReport local_report;
  FeatureDbBuildReport& rep = report ? *report : local_report;
  rep = {};

  FeatureLearner learner;
  LearntDb db;
  for (size_t mi = 0; mi < models.size(); ++mi) {
    SH_RETURN_IF_ERROR(learner.AddModel(models[mi], mi, options, &db, &rep));
  }
  const OrderedFeatures ordered = OrderByKdTree(db.features, options.leaf_size, &rep.tree_depth);
  std::vector<uint8_t> blob = WriteFeatureDb(db, ordered, options);
  rep.views = static_cast<uint32_t>(db.views.size());
  rep.features = static_cast<uint32_t>(ordered.records.size());
  rep.nodes = static_cast<uint32_t>(ordered.nodes.size());
  return blob;
}

}  // namespace sh
