#include "recog/texture/print_verify.hpp"

#include <algorithm>
#include <cmath>

#include "recog/texture/float_planes.hpp"

namespace sh::texture {
namespace {

// Running sums of one face's samples in one image.
struct Correlation {
  double n = 0, st = 0, si = 0, stt = 0, sii = 0, sti = 0;
  void Add(double t, double i) {
    n += 1;
    st += t;
    si += i;
    stt += t * t;
    sii += i * i;
    sti += t * i;
  }
  double TextureStd() const {
    return n > 1 ? std::sqrt(std::max(0.0, stt / n - (st / n) * (st / n))) : 0;
  }
  double Zncc() const {
    const double vt = stt - st * st / n, vi = sii - si * si / n, c = sti - st * si / n;
    return vt > 0 && vi > 0 ? c / std::sqrt(vt * vi) : 0.0;
  }
};

}  // namespace

bool SegmentHitsConvexModel(const Model& model, const RigidTransform& cam_T_model,
                            const Eigen::Vector3f& origin, const Eigen::Vector3f& target,
                            float margin_mm) {
  // Into the model frame; then clip the segment against every face's half-space.
  const RigidTransform model_T_cam = cam_T_model.Inverse();
  const Eigen::Vector3f o = model_T_cam * origin;
  const Eigen::Vector3f d = model_T_cam.Rotate(target - origin);
  const float length = d.norm();
  if (!(length > margin_mm)) return false;
  const Eigen::Vector3f dir = d / length;
  float t_in = 0.0f, t_out = length - margin_mm;
  for (int f = 0; f < model.n_faces; ++f) {
    const Eigen::Vector3f n = model.face_normal(f);
    const float dist = model.faces[f].offset_mm - n.dot(o);  // >= 0: origin inside this face
    const float denom = n.dot(dir);
    if (std::fabs(denom) < 1e-9f) {
      if (dist < 0.0f) return false;  // parallel and outside
      continue;
    }
    const float t = dist / denom;
    if (denom < 0.0f) {
      t_in = std::max(t_in, t);
    } else {
      t_out = std::min(t_out, t);
    }
    if (t_in > t_out) return false;
  }
  return t_in < t_out;
}

void PrintVerifier::Reset(const StereoCalibration* calib, const FeatureDbView* db,
                          ConstGrayView left, ConstGrayView right) {
  calib_ = calib;
  db_ = db;
  images_[0] = left;
  images_[1] = right;
}

PrintScore PrintVerifier::Score(uint32_t model, const RigidTransform& cam_T_model,
                                const PlacedModel* occluders, size_t n_occluders,
                                const PrintVerifyConfig& config) const {
  PrintScore score;
  const StereoCalibration& calib = *calib_;
  const Eigen::Matrix3f right_R_left = calib.right_R_left.cast<float>();
  const Eigen::Vector3f right_t_left = calib.right_t_left_mm.cast<float>();
  const Eigen::Vector3f centres[2] = {Eigen::Vector3f::Zero(),
                                      RightCentreInLeft(calib).cast<float>()};
  const CameraIntrinsics* cams[2] = {&calib.left, &calib.right};
  const float ppm = db_->header().texture_px_per_mm;
  const int step = std::max(1, config.sample_step_texels);
  double weighted[2] = {0, 0}, weight[2] = {0, 0};
  // Bounding spheres of the occluders in the camera frame: most samples miss them, and the
  // sphere test is cheaper than clipping against every face.
  struct Sphere {
    Eigen::Vector3f centre = Eigen::Vector3f::Zero();
    float radius = 0.0f;
  };
  Sphere spheres[kMaxPrintOccluders];
  n_occluders = std::min(n_occluders, kMaxPrintOccluders);
  for (size_t k = 0; k < n_occluders; ++k) {
    const Model& m = *occluders[k].model;
    float radius = 0;
    for (int c = 0; c < m.n_corners; ++c) radius = std::max(radius, m.corner(c).norm());
    spheres[k] = {occluders[k].cam_T_model.t_mm, radius};
  }
  for (uint32_t fi = 0; fi < db_->face_count(); ++fi) {
    const TexturedFace& face = db_->face(fi);
    if (face.model != model) continue;
    const Eigen::Vector3f o(face.origin_mm[0], face.origin_mm[1], face.origin_mm[2]);
    const Eigen::Vector3f a(face.axis_a[0], face.axis_a[1], face.axis_a[2]);
    const Eigen::Vector3f b(face.axis_b[0], face.axis_b[1], face.axis_b[2]);
    const Eigen::Vector3f n_cam = cam_T_model.Rotate(a.cross(b));
    const FaceTexels texels = db_->face_texels(fi);
    const ConstGrayView tex{texels.texels, texels.width, texels.height, texels.width};
    for (int cam = 0; cam < 2; ++cam) {
      // The face must turn towards this camera, and not be seen edge-on: at grazing angles
      // every image pixel mixes many texels (and the face's edges), so the correlation says
      // little. Faces count in proportion to their area in the image (cosine of the angle).
      const Eigen::Vector3f centre_cam =
          cam_T_model * (o + 0.5f * (face.min_ab_mm[0] + face.max_ab_mm[0]) * a +
                         0.5f * (face.min_ab_mm[1] + face.max_ab_mm[1]) * b);
      const float cos_view = -n_cam.dot((centre_cam - centres[cam]).normalized());
      if (cos_view < config.min_view_cosine) continue;
      const ConstGrayView& img = images_[cam];
      Correlation corr;
      for (int j = step / 2; j < tex.height; j += step) {
        const float bb = face.max_ab_mm[1] - (static_cast<float>(j) + 0.5f) / ppm;
        for (int i = step / 2; i < tex.width; i += step) {
          const float aa = face.min_ab_mm[0] + (static_cast<float>(i) + 0.5f) / ppm;
          const Eigen::Vector3f x_cam = cam_T_model * (o + aa * a + bb * b);
          const Eigen::Vector3f x =
              cam == 0 ? x_cam : Eigen::Vector3f(right_R_left * x_cam + right_t_left);
          Eigen::Vector2d px;
          if (!ProjectToPixel(*cams[cam], x.cast<double>(), &px)) continue;
          if (px.x() < 0 || px.y() < 0 || px.x() >= img.width - 1 || px.y() >= img.height - 1)
            continue;
          bool hidden = false;
          for (size_t k = 0; k < n_occluders && !hidden; ++k) {
            // Distance of the sphere's centre from the segment camera -> sample.
            const Eigen::Vector3f d = x_cam - centres[cam];
            const Eigen::Vector3f v = spheres[k].centre - centres[cam];
            const float t = std::clamp(v.dot(d) / d.squaredNorm(), 0.0f, 1.0f);
            if ((v - t * d).squaredNorm() > spheres[k].radius * spheres[k].radius) continue;
            hidden = SegmentHitsConvexModel(*occluders[k].model, occluders[k].cam_T_model,
                                            centres[cam], x_cam, 1.0f);
          }
          if (hidden) {
            ++score.hidden[cam];
            continue;
          }
          corr.Add(tex.at(i, j),
                   SampleGrayInside(img, static_cast<float>(px.x()), static_cast<float>(px.y())));
        }
      }
      if (corr.n < config.min_face_samples || corr.TextureStd() < config.min_texture_std) continue;
      weighted[cam] += cos_view * corr.n * corr.Zncc();
      weight[cam] += cos_view * corr.n;
      score.samples[cam] += static_cast<uint32_t>(corr.n);
      ++score.faces[cam];
    }
  }
  for (int cam = 0; cam < 2; ++cam) {
    if (weight[cam] > 0) score.zncc[cam] = static_cast<float>(weighted[cam] / weight[cam]);
  }
  return score;
}

}  // namespace sh::texture
