#include "hal/sim/world/renderer.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>

#include "hal/sim/world/printed_surface.hpp"
#include "hal/sim/world/ray_caster.hpp"
#include "hal/sim/world/rng.hpp"

namespace sh::render {
namespace {

constexpr float kShadowRayOffsetMm = 1e-2f;  // offset of secondary rays from the surface
constexpr float kEnvironment = 0.06f;        // radiance of rays leaving the scene (dim room)
constexpr float kObjectSpecular = 0.18f;     // Blinn-Phong weight and exponent of the objects
constexpr int kObjectShininess = 32;         // powers of two: evaluated by squaring
constexpr int kMaxSupersampling = 8;

struct TableFinish {
  float albedo, specular;
  int shininess;
  float mirror;
};
constexpr TableFinish kDarkTable = {0.07f, 0.02f, 8, 0.0f};
constexpr TableFinish kLightTable = {0.62f, 0.05f, 16, 0.18f};

// A value on the 0..255 scale to an 8-bit code, rounded and clipped.
uint8_t ToByte(float v) {
  return static_cast<uint8_t>(std::lround(std::min(255.0f, std::max(0.0f, v))));
}

// x^n for n a power of two (cheaper than pow, and bit-identical everywhere).
float PowerOfTwoPow(float x, int n) {
  for (; n > 1; n >>= 1) x *= x;
  return x;
}

// Undistorted normalised coordinates of a pixel, by the fixed-point iteration of UndistortPixel
// started from a neighbouring solution: a few rounds reach its accuracy (each round shrinks the
// error by about |k1| r^2 < 0.05), which matters because every pixel corner needs one.
Eigen::Vector2d UndistortFrom(const CameraIntrinsics& cam, const Eigen::Vector2d& pixel,
                              const Eigen::Vector2d& guess) {
  const Eigen::Vector2d distorted((pixel.x() - cam.cx) / cam.fx, (pixel.y() - cam.cy) / cam.fy);
  Eigen::Vector2d xy = guess;
  for (int i = 0; i < 5; ++i) {
    const double x = xy.x(), y = xy.y();
    const double r2 = x * x + y * y;
    const double radial = 1.0 + r2 * (cam.k1 + r2 * (cam.k2 + r2 * cam.k3));
    const double dx = 2.0 * cam.p1 * x * y + cam.p2 * (r2 + 2.0 * x * x);
    const double dy = cam.p1 * (r2 + 2.0 * y * y) + 2.0 * cam.p2 * x * y;
    xy = {(distorted.x() - dx) / radial, (distorted.y() - dy) / radial};
  }
  return xy;
}

// 10-bit code of what a ray sees (object or table, face), plus two shadow bits; two codes (direct
// view and mirror image) identify the piecewise-smooth region a sample belongs to.
uint32_t SurfaceCode(int object, int face) {
  const uint32_t o = object == kTableHit ? 31u : object == kNoHit ? 30u : uint32_t(object);
  return o | (uint32_t(face) << 5);
}

// Linear radiance per channel (R, G, B), 1.0 = white. Grey scenes keep the three equal.
using Radiance = Eigen::Array3f;

struct Sample {
  Radiance value = Radiance::Zero();
  uint32_t code = 0;
};

// The grey a camera without colour filters sees: a grey radiance as it is (so grey scenes keep
// their exact bytes), a coloured one weighted with the BT.601 luma weights.
float GreyOf(const Radiance& v) {
  if (v[0] == v[1] && v[1] == v[2]) return v[0];
  return 0.299f * v[0] + 0.587f * v[1] + 0.114f * v[2];
}

class Shader {
 public:
  Shader(const RenderScene& scene, const RayCaster& caster)
      : scene_(scene),
        caster_(caster),
        table_(scene.background == Background::kLight ? kLightTable : kDarkTable) {}

  Sample Trace(const Eigen::Vector3f& o, const Eigen::Vector3f& d, bool allow_mirror) const {
    const Hit hit = caster_.Cast(o, d);
    Sample s;
    if (hit.object == kNoHit) {
      s.value = Radiance::Constant(kEnvironment);
      s.code = SurfaceCode(kNoHit, 0);
      return s;
    }
    const bool is_table = hit.object == kTableHit;
    const Eigen::Vector3f p = o + hit.t_mm * d;
    const Eigen::Vector3f n = caster_.normal(hit);
    float albedo = is_table ? table_.albedo : caster_.albedo(hit.object);
    Radiance colour = Radiance::Ones();
    if (!is_table) {
      const SceneObject& object = scene_.objects[static_cast<size_t>(hit.object)];
      if (object.print != nullptr) {
        albedo *= object.print->Reflectance(hit.face, object.table_T_model.Inverse() * p);
      }
      colour = object.colour.array();
    }
    const float ks = is_table ? table_.specular : kObjectSpecular;
    const int shininess = is_table ? table_.shininess : kObjectShininess;
    float diffuse = scene_.ambient, specular = 0;
    uint32_t shadow_bits = 0;
    for (int k = 0; k < 2; ++k) {
      const PointLight& light = scene_.lights[k];
      const Eigen::Vector3f to_light = light.position_table_mm - p;
      const float distance = to_light.norm();
      const Eigen::Vector3f l = to_light / distance;
      const float cos_in = n.dot(l);
      if (cos_in <= 0) continue;
      if (caster_.Blocked(p + kShadowRayOffsetMm * n, l, distance)) {
        shadow_bits |= 1u << k;
        continue;
      }
      diffuse += light.intensity * cos_in;
      const float cos_half = n.dot((l - d).normalized());
      if (cos_half > 0) specular += light.intensity * PowerOfTwoPow(cos_half, shininess);
    }
    s.value = (albedo * colour) * diffuse + ks * specular;
    s.code = SurfaceCode(hit.object, hit.face) | (shadow_bits << 10);
    if (is_table && allow_mirror && table_.mirror > 0) {
      const Eigen::Vector3f mirrored(d.x(), d.y(), -d.z());
      const Sample r = Trace(p + kShadowRayOffsetMm * n, mirrored, false);
      s.value = (1 - table_.mirror) * s.value + table_.mirror * r.value;
      s.code |= r.code << 12;
    }
    return s;
  }

 private:
  const RenderScene& scene_;
  const RayCaster& caster_;
  TableFinish table_;
};

// Ray geometry of one camera in the table frame.
struct CameraRays {
  Eigen::Matrix3f table_R_cam;
  Eigen::Vector3f centre_table;

  Eigen::Vector3f Direction(const Eigen::Vector2f& xy_norm) const {
    return table_R_cam * Eigen::Vector3f(xy_norm.x(), xy_norm.y(), 1.0f).normalized();
  }
};

Status CheckTarget(const char* what, int width, int height, int tw, int th) {
  if (tw != width || th != height) {
    return Status::Error(StatusCode::kInvalidArgument,
                         "render: %s view is %d x %d but the camera is %d x %d", what, tw, th,
                         width, height);
  }
  return Status::Ok();
}

}  // namespace

RigidTransform RightFromTable(const RenderScene& scene, const StereoCalibration& calib) {
  RigidTransform right_T_left;
  right_T_left.R = calib.right_R_left.cast<float>();
  right_T_left.t_mm = calib.right_t_left_mm.cast<float>();
  return right_T_left * scene.left_T_table;
}

Status RenderView(const RenderScene& scene, const Model* models, int n_models,
                  const CameraIntrinsics& camera, const RigidTransform& cam_T_table,
                  int camera_index, const RenderTargets& targets) {
  const int width = camera.width, height = camera.height;
  if (width <= 0 || height <= 0 || width > kMaxImageWidth || height > kMaxImageHeight) {
    return Status::Error(StatusCode::kOutOfRange, "render: camera size %d x %d not supported",
                         width, height);
  }
  if (targets.image.empty() && targets.rgb.empty()) {
    return Status::Error(StatusCode::kInvalidArgument, "render: no output image");
  }
  if (!targets.image.empty()) {
    SH_RETURN_IF_ERROR(
        CheckTarget("image", width, height, targets.image.width, targets.image.height));
  }
  if (!targets.rgb.empty()) {
    SH_RETURN_IF_ERROR(CheckTarget("rgb", width, height, targets.rgb.width, targets.rgb.height));
  }
  if (!targets.labels.empty()) {
    SH_RETURN_IF_ERROR(
        CheckTarget("label", width, height, targets.labels.width, targets.labels.height));
  }
  if (!targets.depth_mm.empty()) {
    SH_RETURN_IF_ERROR(
        CheckTarget("depth", width, height, targets.depth_mm.width, targets.depth_mm.height));
  }
  if (scene.supersampling < 1 || scene.supersampling > kMaxSupersampling) {
    return Status::Error(StatusCode::kOutOfRange, "render: supersampling %d outside 1..%d",
                         scene.supersampling, kMaxSupersampling);
  }
  if (!(camera.fx > 0 && camera.fy > 0)) {
    return Status::Error(StatusCode::kInvalidArgument, "render: focal length must be positive");
  }

  RayCaster caster;
  SH_RETURN_IF_ERROR(caster.Prepare(scene, models, n_models));
  const Shader shader(scene, caster);
  CameraRays rays;
  const RigidTransform table_T_cam = cam_T_table.Inverse();
  rays.table_R_cam = table_T_cam.R;
  rays.centre_table = table_T_cam.t_mm;

  // Two rows of pixel-corner samples (corner (i, j) is at pixel coordinates (i - 0.5, j - 0.5);
  // pixel centres are at integer coordinates as in OpenCV).
  struct CornerRow {
    Eigen::Vector2f xy[kMaxImageWidth + 1];  // undistorted normalised coordinates
    Sample sample[kMaxImageWidth + 1];
  };
  static_assert(sizeof(CornerRow) < size_t{32} * 1024,
                "corner rows are meant to live on the stack");
  CornerRow rows[2];
  auto fill_row = [&](CornerRow& row, int j) {
    Eigen::Vector2d xy = UndistortPixel(camera, {-0.5, j - 0.5});
    for (int i = 0; i <= width; ++i) {
      if (i > 0) xy = UndistortFrom(camera, {i - 0.5, j - 0.5}, xy);
      row.xy[i] = xy.cast<float>();
      row.sample[i] = shader.Trace(rays.centre_table, rays.Direction(row.xy[i]), true);
    }
  };
  fill_row(rows[0], 0);
  const int n = scene.supersampling;
  const uint64_t noise_stream = Mix64(scene.seed ^ (uint64_t(camera_index + 1) << 56));
  for (int y = 0; y < height; ++y) {
    CornerRow& top = rows[y & 1];
    CornerRow& bottom = rows[(y + 1) & 1];
    fill_row(bottom, y + 1);
    uint8_t* out = targets.image.empty() ? nullptr : targets.image.row(y);
    Rgb8* out_rgb = targets.rgb.empty() ? nullptr : targets.rgb.row(y);
    for (int x = 0; x < width; ++x) {
      const Sample& a = top.sample[x];
      const Sample& b = top.sample[x + 1];
      const Sample& c = bottom.sample[x];
      const Sample& d = bottom.sample[x + 1];
      // Bilinear interpolation of the undistorted coordinates inside the pixel: the distortion
      // is smooth, its curvature over one pixel is far below 1e-3 px.
      auto xy_at = [&](float fx, float fy) {
        return ((1 - fy) * ((1 - fx) * top.xy[x] + fx * top.xy[x + 1]) +
                fy * ((1 - fx) * bottom.xy[x] + fx * bottom.xy[x + 1]))
            .eval();
      };
      Radiance value;
      if (a.code == b.code && a.code == c.code && a.code == d.code) {
        value = 0.25f * (a.value + b.value + c.value + d.value);
      } else {
        Radiance sum = Radiance::Zero();
        for (int sj = 0; sj < n; ++sj) {
          for (int si = 0; si < n; ++si) {
            const Eigen::Vector2f xy = xy_at((si + 0.5f) / n, (sj + 0.5f) / n);
            sum += shader.Trace(rays.centre_table, rays.Direction(xy), true).value;
          }
        }
        value = sum / static_cast<float>(n * n);
      }
      const uint64_t pixel_hash = Mix64(noise_stream + uint64_t(y) * uint64_t(width) + uint64_t(x));
      if (out != nullptr) {
        out[x] = ToByte(255.0f * GreyOf(value) + scene.noise_sigma * GaussianFromHash(pixel_hash));
      }
      if (out_rgb != nullptr) {
        // Each colour site has its own noise: the grey stream's draw for red, further draws of
        // the same pixel's hash for green and blue.
        uint8_t rgb[3];
        for (int k = 0; k < 3; ++k) {
          const uint64_t h = k == 0 ? pixel_hash : Mix64(pixel_hash + uint64_t(k));
          rgb[k] = ToByte(255.0f * value[k] + scene.noise_sigma * GaussianFromHash(h));
        }
        out_rgb[x] = Rgb8{rgb[0], rgb[1], rgb[2]};
      }

      if (!targets.labels.empty() || !targets.depth_mm.empty()) {
        const Eigen::Vector2f xy = xy_at(0.5f, 0.5f);
        const Hit hit = caster.Cast(rays.centre_table, rays.Direction(xy));
        const bool is_object = hit.object != kTableHit && hit.object != kNoHit;
        if (!targets.labels.empty()) {
          targets.labels.at(x, y) = is_object ? static_cast<uint8_t>(hit.object + 1) : kTableLabel;
        }
        if (!targets.depth_mm.empty()) {
          // Camera-frame z of the hit: t along the unit ray times the ray's z component.
          const float z_per_t = 1.0f / Eigen::Vector3f(xy.x(), xy.y(), 1.0f).norm();
          targets.depth_mm.at(x, y) =
              hit.object == kNoHit ? std::numeric_limits<float>::infinity() : hit.t_mm * z_per_t;
        }
      }
    }
  }
  return Status::Ok();
}

Status RenderStereo(const RenderScene& scene, const Model* models, int n_models,
                    const StereoCalibration& calib, const RenderTargets& left,
                    const RenderTargets& right) {
  SH_RETURN_IF_ERROR(RenderView(scene, models, n_models, calib.left, scene.left_T_table, 0, left));
  return RenderView(scene, models, n_models, calib.right, RightFromTable(scene, calib), 1, right);
}

Status RenderStereo(const RenderScene& scene, const Model* models, int n_models,
                    const StereoCalibration& calib, GrayView left, GrayView right) {
  RenderTargets l, r;
  l.image = left;
  r.image = right;
  return RenderStereo(scene, models, n_models, calib, l, r);
}

}  // namespace sh::render
