#include "tests/shape/flat_scene.hpp"

#include <algorithm>
#include <cmath>

#include "recog/verify/visible_edges.hpp"

namespace sh::testing {
namespace {

constexpr int kSuper = 3;  // samples per pixel and axis

struct Face {
  float depth;
  int n;
  float px[kMaxFaceVertices][2];  // supersampled pixel coordinates
  Rgb8 colour;
};

uint64_t Mix(uint64_t z) {
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
  return z ^ (z >> 31);
}

float Gauss(uint64_t h) {  // Irwin-Hall approximation from a hash
  float sum = 0;
  for (int k = 0; k < 12; ++k) {
    h = Mix(h + 0x9e3779b97f4a7c15ull);
    sum += static_cast<float>(h >> 40) * (1.0f / 16777216.0f);
  }
  return sum - 6.0f;
}

void RenderOne(const ViewCamera& view, const std::vector<FlatPart>& parts, uint8_t table_grey,
               float noise, int camera_index, FlatImage* out) {
  const CameraIntrinsics& cam = view.intrinsics;
  const int W = cam.width * kSuper, H = cam.height * kSuper;
  std::vector<float> acc(static_cast<size_t>(W) * H * 3);
  for (size_t i = 0; i < acc.size(); ++i) acc[i] = table_grey;
  const Eigen::Vector3f light = Eigen::Vector3f(-0.3f, -0.8f, -0.5f).normalized();
  const double max_r2 = MaxImageRadius2(cam);
  std::vector<Face> faces;
  for (const FlatPart& part : parts) {
    const Model& m = *part.posed.model;
    const RigidTransform cam_T_model = view.cam_T_left * part.posed.cam_T_model;
    const Eigen::Vector3f centre = cam_T_model.Inverse().t_mm;
    for (int f = 0; f < m.n_faces; ++f) {
      if (m.face_normal(f).dot(centre) - m.faces[f].offset_mm <= 0) continue;
      Face face;
      face.n = m.faces[f].n_vertices;
      face.depth = 0;
      bool ok = true;
      for (int k = 0; k < face.n; ++k) {
        const Eigen::Vector3f x = cam_T_model * m.corner(m.faces[f].vertices[k]);
        Eigen::Vector2f p;
        ok &= ProjectInView(cam, max_r2, x, &p);
        // Supersampled coordinates: sample (i, j) of pixel (x, y) is at x - 1/3 + i / 3 ...
        face.px[k][0] = (p.x() + 0.5f) * kSuper - 0.5f;
        face.px[k][1] = (p.y() + 0.5f) * kSuper - 0.5f;
        face.depth += x.z() / face.n;
      }
      if (!ok) continue;
      const float shade =
          0.25f + 0.75f * std::max(0.0f, cam_T_model.Rotate(m.face_normal(f)).dot(light));
      auto encode = [&](float linear) {
        return static_cast<uint8_t>(
            std::lround(255.0f * std::pow(std::min(1.0f, linear * shade), 1.0f / 2.2f)));
      };
      face.colour = {encode(part.kd[0]), encode(part.kd[1]), encode(part.kd[2])};
      faces.push_back(face);
    }
  }
  std::sort(faces.begin(), faces.end(),
            [](const Face& a, const Face& b) { return a.depth > b.depth; });
  for (const Face& face : faces) {
    float ymin = 1e9f, ymax = -1e9f;
    for (int k = 0; k < face.n; ++k) {
      ymin = std::min(ymin, face.px[k][1]);
      ymax = std::max(ymax, face.px[k][1]);
    }
    for (int y = std::max(0, static_cast<int>(std::ceil(ymin)));
         y <= std::min(H - 1, static_cast<int>(std::floor(ymax))); ++y) {
      float xs[kMaxFaceVertices];
      int n = 0;
      for (int k = 0, j = face.n - 1; k < face.n; j = k++) {
        const float* a = face.px[j];
        const float* b = face.px[k];
        if ((a[1] <= y) != (b[1] <= y)) xs[n++] = a[0] + (y - a[1]) * (b[0] - a[0]) / (b[1] - a[1]);
      }
      std::sort(xs, xs + n);
      for (int i = 0; i + 1 < n; i += 2) {
        for (int x = std::max(0, static_cast<int>(std::ceil(xs[i])));
             x < std::min(W, static_cast<int>(std::ceil(xs[i + 1]))); ++x) {
          float* a = &acc[(static_cast<size_t>(y) * W + x) * 3];
          a[0] = face.colour.r;
          a[1] = face.colour.g;
          a[2] = face.colour.b;
        }
      }
    }
  }
  out->width = cam.width;
  out->height = cam.height;
  out->rgb.assign(static_cast<size_t>(cam.width) * cam.height, Rgb8{});
  for (int y = 0; y < cam.height; ++y) {
    for (int x = 0; x < cam.width; ++x) {
      float sum[3] = {0, 0, 0};
      for (int j = 0; j < kSuper; ++j) {
        for (int i = 0; i < kSuper; ++i) {
          const float* a = &acc[(static_cast<size_t>(y * kSuper + j) * W + x * kSuper + i) * 3];
          for (int c = 0; c < 3; ++c) sum[c] += a[c];
        }
      }
      uint8_t v[3];
      for (int c = 0; c < 3; ++c) {
        const uint64_t h = Mix((uint64_t(camera_index) << 60) ^ (uint64_t(y) << 32) ^
                               (uint64_t(x) << 4) ^ uint64_t(c));
        const float value = sum[c] / (kSuper * kSuper) + noise * Gauss(h);
        v[c] = static_cast<uint8_t>(std::lround(std::min(255.0f, std::max(0.0f, value))));
      }
      out->rgb[static_cast<size_t>(y) * cam.width + x] = {v[0], v[1], v[2]};
    }
  }
}

}  // namespace

StereoCalibration ThesisRig() {
  StereoCalibration c;
  for (CameraIntrinsics* cam : {&c.left, &c.right}) {
    cam->width = 756;
    cam->height = 581;
    cam->fx = cam->fy = 1136.36363636;
    cam->cx = 377.5;
    cam->cy = 290.0;
  }
  c.right_R_left << 0.945945945946, -0.20176584785, 0.253922842592, 0.20176584785, 0.979079862191,
      0.0263280476679, -0.253922842592, 0.0263280476679, 0.966866083755;
  c.right_t_left_mm << -118.36727086, -12.2729373919, 15.445523525;
  return c;
}

void RenderFlatPair(const StereoCalibration& calib, const std::vector<FlatPart>& parts,
                    uint8_t table_grey, float noise, FlatImage* left, FlatImage* right) {
  RenderOne(LeftView(calib), parts, table_grey, noise, 0, left);
  RenderOne(RightView(calib), parts, table_grey, noise, 1, right);
}

}  // namespace sh::testing
