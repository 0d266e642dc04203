#include "hal/sim/world/scene_generator.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstring>

#include "hal/sim/world/rng.hpp"
#include "recog/geometry/convex_hull.hpp"

namespace sh::render {
namespace {

constexpr float kPi = 3.14159265358979f;
constexpr int kPlacementTries = 400;  // per object
constexpr int kSceneTries = 40;       // whole-scene restarts
constexpr float kImageMarginPx = 12.0f;

// 2-D convex polygon (counter-clockwise), for footprints on the table and silhouettes in images.
// NOLINTNEXTLINE(bugprone-reserved-identifier): clang-tidy 14 names the implicit array copy's index
struct Hull {
  int n = 0;
  Eigen::Vector2f p[kMaxModelCorners];
};

Hull ConvexHull(const Eigen::Vector2f* points, int n) {
  Eigen::Vector2f sorted[kMaxModelCorners];
  std::copy(points, points + n, sorted);
  Eigen::Vector2f chain[2 * kMaxModelCorners];
  Hull hull;
  hull.n = std::min(ConvexHull2D(sorted, n, chain), kMaxModelCorners);
  std::copy(chain, chain + hull.n, hull.p);
  return hull;
}

// Largest gap between the two polygons along the edge normals of either: a lower bound of their
// distance (<= 0 when they overlap).
float Separation(const Hull& a, const Hull& b) {
  float best = -1e30f;
  for (const Hull* h : {&a, &b}) {
    for (int i = 0; i < h->n; ++i) {
      const Eigen::Vector2f e = h->p[(i + 1) % h->n] - h->p[i];
      const Eigen::Vector2f axis = Eigen::Vector2f(e.y(), -e.x()).normalized();
      float amin = 1e30f, amax = -1e30f, bmin = 1e30f, bmax = -1e30f;
      for (int k = 0; k < a.n; ++k) {
        amin = std::min(amin, axis.dot(a.p[k]));
        amax = std::max(amax, axis.dot(a.p[k]));
      }
      for (int k = 0; k < b.n; ++k) {
        bmin = std::min(bmin, axis.dot(b.p[k]));
        bmax = std::max(bmax, axis.dot(b.p[k]));
      }
      best = std::max(best, std::max(bmin - amax, amin - bmax));
    }
  }
  return best;
}

bool InsidePolygon2d(const Eigen::Vector2f* poly, int n, const Eigen::Vector2f& q, float margin) {
  bool inside = false;
  for (int i = 0, j = n - 1; i < n; j = i++) {
    const Eigen::Vector2f& a = poly[j];
    const Eigen::Vector2f& b = poly[i];
    if ((b.y() > q.y()) != (a.y() > q.y()) &&
        q.x() < (a.x() - b.x()) * (q.y() - b.y()) / (a.y() - b.y()) + b.x()) {
      inside = !inside;
    }
    // Distance from q to the edge.
    const Eigen::Vector2f e = b - a;
    const float t = std::clamp((q - a).dot(e) / e.squaredNorm(), 0.0f, 1.0f);
    if ((a + t * e - q).norm() < margin) return false;
  }
  return inside;
}

CameraIntrinsics ThesisCamera(double fx, double cx, double cy, double k1, double k2, double p1,
                              double p2) {
  CameraIntrinsics c;
  c.width = 756;
  c.height = 581;
  c.fx = fx;
  c.fy = fx;  // square pixels (11 um x 11 um)
  c.cx = cx;
  c.cy = cy;
  c.k1 = k1;
  c.k2 = k2;
  c.p1 = p1;
  c.p2 = p2;
  return c;
}

// Camera at `centre` looking at `target`, image x axis along `across` (table frame).
RigidTransform LookAt(const Eigen::Vector3f& centre, const Eigen::Vector3f& target,
                      const Eigen::Vector3f& across) {
  const Eigen::Vector3f z = (target - centre).normalized();
  const Eigen::Vector3f x = (across - across.dot(z) * z).normalized();
  const Eigen::Vector3f y = z.cross(x);
  RigidTransform table_T_cam;
  table_T_cam.R.col(0) = x;
  table_T_cam.R.col(1) = y;
  table_T_cam.R.col(2) = z;
  table_T_cam.t_mm = centre;
  return table_T_cam.Inverse();
}

struct Rig {
  StereoCalibration calib;
  RigidTransform left_T_table, right_T_table;
};

// A converging pair: the rig centre sits `distance` from the table origin, tilted by `tilt`
// from the vertical, both cameras aimed at the origin, baseline along the table x axis.
Rig MakeRig(const ScenarioParams& params, float tilt_rad) {
  const float distance_mm = params.camera_distance_mm, baseline_mm = params.baseline_mm;
  Rig rig;
  if (params.custom_camera) {
    rig.calib.left = params.camera;
    rig.calib.right = params.camera;
    rig.calib.right.fx *= 0.996;
    rig.calib.right.fy *= 0.996;
    rig.calib.right.cx -= 3.3;
    rig.calib.right.cy += 2.7;
    rig.calib.right.k1 *= 0.95;
    rig.calib.right.k2 *= 0.95;
  } else {
    // 12.5 mm lens / 11 um pixels = 1136.4 px; the right camera differs slightly, as real ones
    // do.
    rig.calib.left = ThesisCamera(1136.4, 379.2, 289.6, -0.10, 0.06, 0.0002, -0.0001);
    rig.calib.right = ThesisCamera(1131.8, 375.9, 292.3, -0.095, 0.05, -0.0001, 0.0002);
  }
  const Eigen::Vector3f centre(0, -distance_mm * std::sin(tilt_rad),
                               distance_mm * std::cos(tilt_rad));
  const Eigen::Vector3f across = Eigen::Vector3f::UnitX();
  rig.left_T_table = LookAt(centre - 0.5f * baseline_mm * across, Eigen::Vector3f::Zero(), across);
  rig.right_T_table = LookAt(centre + 0.5f * baseline_mm * across, Eigen::Vector3f::Zero(), across);
  const RigidTransform right_T_left = rig.right_T_table * rig.left_T_table.Inverse();
  rig.calib.right_R_left = right_T_left.R.cast<double>();
  rig.calib.right_t_left_mm = right_T_left.t_mm.cast<double>();
  return rig;
}

// NOLINTNEXTLINE(bugprone-reserved-identifier): clang-tidy 14 names the implicit array copy's index
struct Candidate {
  RigidTransform table_T_model;
  Hull footprint;      // on the table (x, y)
  Hull silhouette[2];  // convex hull of the projected corners in the left and right image
};

// Places a model on a random stable face at (x, y) with a random heading; false if it does not
// project fully inside both images.
bool MakeCandidate(const Model& model, const int* stable, int n_stable, const float* areas,
                   Rng& rng, const Eigen::Vector2f& xy, const Rig& rig, Candidate* c) {
  float total = 0;
  for (int i = 0; i < n_stable; ++i) total += areas[i];
  float pick = rng.Uniform() * total;
  int f = stable[n_stable - 1];
  for (int i = 0; i < n_stable; ++i) {
    if (pick < areas[i]) {
      f = stable[i];
      break;
    }
    pick -= areas[i];
  }
  // Rotate the resting face's outward normal onto -z (face down), then spin about z.
  const Eigen::Matrix3f down =
      Eigen::Quaternionf::FromTwoVectors(model.face_normal(f), -Eigen::Vector3f::UnitZ())
          .toRotationMatrix();
  const float heading = rng.Uniform(0.0f, 2 * kPi);
  c->table_T_model.R =
      Eigen::AngleAxisf(heading, Eigen::Vector3f::UnitZ()).toRotationMatrix() * down;
  // Face points satisfy normal . x = offset, i.e. z = -offset after the rotation.
  c->table_T_model.t_mm = Eigen::Vector3f(xy.x(), xy.y(), model.faces[f].offset_mm);
  Orthonormalize(c->table_T_model);

  Eigen::Vector2f table_xy[kMaxModelCorners], image_xy[2][kMaxModelCorners];
  for (int i = 0; i < model.n_corners; ++i) {
    const Eigen::Vector3f p = c->table_T_model * model.corner(i);
    table_xy[i] = p.head<2>();
    for (int cam = 0; cam < 2; ++cam) {
      const RigidTransform& cam_T_table = cam == 0 ? rig.left_T_table : rig.right_T_table;
      const CameraIntrinsics& intr = cam == 0 ? rig.calib.left : rig.calib.right;
      Eigen::Vector2d px;
      if (!ProjectToPixel(intr, (cam_T_table * p).cast<double>(), &px)) return false;
      if (px.x() < kImageMarginPx || px.y() < kImageMarginPx ||
          px.x() > intr.width - 1 - kImageMarginPx || px.y() > intr.height - 1 - kImageMarginPx) {
        return false;
      }
      image_xy[cam][i] = px.cast<float>();
    }
  }
  c->footprint = ConvexHull(table_xy, model.n_corners);
  for (int cam = 0; cam < 2; ++cam) c->silhouette[cam] = ConvexHull(image_xy[cam], model.n_corners);
  return true;
}

float FaceArea(const Model& m, int f) {
  Eigen::Vector3f sum = Eigen::Vector3f::Zero();
  const ModelFace& face = m.faces[f];
  for (int k = 0; k < face.n_vertices; ++k) {
    sum += m.corner(face.vertices[k]).cross(m.corner(face.vertices[(k + 1) % face.n_vertices]));
  }
  return 0.5f * std::abs(sum.dot(m.face_normal(f)));
}

}  // namespace

bool NamedCamera(const char* name, ScenarioParams* params) {
  CameraIntrinsics c;
  if (std::strcmp(name, "thesis") == 0) {
    params->custom_camera = false;
    return true;
  } else if (std::strcmp(name, "wide") == 0) {
    c.width = 1024, c.height = 768;
    c.fx = 760.0, c.fy = 758.5, c.cx = 531.0, c.cy = 371.5;
    c.k1 = -0.26, c.k2 = 0.08, c.p1 = 0.0008, c.p2 = -0.0006, c.k3 = -0.01;
  } else if (std::strcmp(name, "tele") == 0) {
    c.width = 640, c.height = 480;
    c.fx = 1500.0, c.fy = 1500.0, c.cx = 315.5, c.cy = 243.0;
    c.k1 = 0.05, c.k2 = 0.0;
  } else if (std::strcmp(name, "hd") == 0) {
    c.width = 1280, c.height = 1024;
    c.fx = 1700.0, c.fy = 1702.0, c.cx = 648.0, c.cy = 505.0;
    c.k1 = -0.12, c.k2 = 0.05, c.p1 = -0.0005, c.p2 = 0.0004;
  } else {
    return false;
  }
  params->custom_camera = true;
  params->camera = c;
  return true;
}

int StableFaces(const Model& model, int* faces) {
  Eigen::Vector3f centroid = Eigen::Vector3f::Zero();
  for (int i = 0; i < model.n_corners; ++i) centroid += model.corner(i);
  centroid /= static_cast<float>(std::max<int>(1, model.n_corners));
  int n = 0;
  for (int f = 0; f < model.n_faces; ++f) {
    const Eigen::Vector3f normal = model.face_normal(f);
    const float offset = model.faces[f].offset_mm;
    bool supporting = true;
    for (int i = 0; i < model.n_corners; ++i) {
      supporting &= normal.dot(model.corner(i)) <= offset + 1e-3f;
    }
    if (!supporting) continue;
    // The centroid (uniform density) must project well inside the face to rest there.
    int drop = 0;
    normal.cwiseAbs().maxCoeff(&drop);
    const int u = (drop + 1) % 3, v = (drop + 2) % 3;
    Eigen::Vector2f poly[kMaxFaceVertices];
    const ModelFace& face = model.faces[f];
    for (int k = 0; k < face.n_vertices; ++k) {
      const Eigen::Vector3f c = model.corner(face.vertices[k]);
      poly[k] = {c[u], c[v]};
    }
    const Eigen::Vector3f projected = centroid - (normal.dot(centroid) - offset) * normal;
    if (InsidePolygon2d(poly, face.n_vertices, {projected[u], projected[v]}, 2.0f)) faces[n++] = f;
  }
  return n;
}

Result<GeneratedScene> GenerateScene(uint64_t seed, const ScenarioParams& params,
                                     const Model* models, int n_models) {
  if (n_models <= 0 || models == nullptr) {
    return Status::Error(StatusCode::kInvalidArgument, "scene: no models");
  }
  if (params.n_objects < 1 || params.n_objects > kMaxRenderObjects) {
    return Status::Error(StatusCode::kOutOfRange, "scene: %d objects, expected 1..%d",
                         params.n_objects, kMaxRenderObjects);
  }
  if (!(params.camera_distance_mm >= 200 && params.camera_distance_mm <= 600)) {
    return Status::Error(StatusCode::kOutOfRange,
                         "scene: camera distance %.0f mm outside 200..600 mm",
                         params.camera_distance_mm);
  }
  if (!(params.baseline_mm > 0 && params.baseline_mm <= 400) || !(params.spread_mm > 0) ||
      !(params.noise_sigma >= 0 && params.noise_sigma <= 50)) {
    return Status::Error(StatusCode::kOutOfRange, "scene: baseline, spread or noise out of range");
  }
  if (!(params.tilt_deg <= 60.0f)) {  // negative: drawn per scene; NaN refused
    return Status::Error(StatusCode::kOutOfRange, "scene: tilt %g degrees is above 60",
                         double(params.tilt_deg));
  }
  int stable[64][kMaxModelFaces];
  float areas[64][kMaxModelFaces];
  int n_stable[64] = {};
  if (n_models > 64) return Status::Error(StatusCode::kOutOfRange, "scene: more than 64 models");
  for (int m = 0; m < n_models; ++m) {
    n_stable[m] = StableFaces(models[m], stable[m]);
    if (n_stable[m] == 0) {
      return Status::Error(StatusCode::kInvalidArgument, "scene: model '%s' has no stable face",
                           models[m].name);
    }
    for (int i = 0; i < n_stable[m]; ++i) areas[m][i] = FaceArea(models[m], stable[m][i]);
  }

  Rng rng(Mix64(seed) ^ 0x5ce7e5ce7e5ce7e5ull);
  // Drawn even when fixed, so that a fixed tilt leaves the rest of the scene as drawn.
  float tilt_deg = rng.Uniform(12.0f, 22.0f);
  if (params.tilt_deg >= 0.0f) tilt_deg = params.tilt_deg;
  const Rig rig = MakeRig(params, tilt_deg * kPi / 180.0f);

  // How tightly objects are packed, and how many overlapping pairs the left image must show.
  float spread_factor = 1.0f, gap_mm = 15.0f;
  int min_overlaps = 0;
  switch (params.occlusion) {
    case Occlusion::kNone:
      break;
    case Occlusion::kSome:
      spread_factor = 0.55f;
      gap_mm = 2.0f;
      min_overlaps = params.n_objects >= 2 ? 1 : 0;
      break;
    case Occlusion::kSevere:
      spread_factor = 0.3f;
      gap_mm = 0.5f;
      min_overlaps = params.n_objects >= 3 ? 2 : params.n_objects - 1;
      break;
  }
  const float half_side = 0.5f * params.spread_mm * spread_factor;

  for (int attempt = 0; attempt < kSceneTries; ++attempt) {
    GeneratedScene out;
    out.calib = rig.calib;
    out.tilt_deg = tilt_deg;
    out.scene.left_T_table = rig.left_T_table;
    out.scene.background = params.background;
    out.scene.noise_sigma = params.noise_sigma;
    out.scene.seed = seed;
    // Two lights above the table, on either side, at slightly random places.
    out.scene.lights[0].position_table_mm = {rng.Uniform(-350, -200), rng.Uniform(-300, -100),
                                             rng.Uniform(650, 850)};
    out.scene.lights[0].intensity = 0.55f;
    out.scene.lights[1].position_table_mm = {rng.Uniform(200, 350), rng.Uniform(100, 300),
                                             rng.Uniform(700, 900)};
    out.scene.lights[1].intensity = 0.40f;

    // Distinct models while there are enough, in random order. The shuffle starts from the
    // models in name order, so a seed gives the same scene whatever the folder's model order.
    int order[64];
    for (int m = 0; m < n_models; ++m) order[m] = m;
    std::sort(order, order + n_models,
              [models](int a, int b) { return std::strcmp(models[a].name, models[b].name) < 0; });
    for (int m = n_models - 1; m > 0; --m) std::swap(order[m], order[rng.Below(m + 1)]);

    Candidate placed[kMaxRenderObjects];
    int n_placed = 0;
    for (int i = 0; i < params.n_objects; ++i) {
      const int m = order[i % n_models];
      bool ok = false;
      for (int t = 0; t < kPlacementTries && !ok; ++t) {
        // One draw a statement, y before x: the order in which a call's arguments are evaluated
        // is the compiler's to choose (GCC takes them last to first on x86-64 and first to last
        // on AArch64), and a seed's scene must be the same on every build.
        const float y = rng.Uniform(-half_side, half_side);
        const float x = rng.Uniform(-half_side, half_side);
        const Eigen::Vector2f xy(x, y);
        Candidate c;
        if (!MakeCandidate(models[m], stable[m], n_stable[m], areas[m], rng, xy, rig, &c)) continue;
        ok = true;
        for (int j = 0; j < n_placed && ok; ++j) {
          ok = Separation(c.footprint, placed[j].footprint) >= gap_mm;
          if (ok && params.occlusion == Occlusion::kNone) {
            for (int cam = 0; cam < 2; ++cam) {
              ok &= Separation(c.silhouette[cam], placed[j].silhouette[cam]) >= 4.0f;
            }
          }
        }
        if (ok) placed[n_placed] = c;
      }
      if (!ok) break;
      SceneObject so;
      so.model_index = static_cast<uint16_t>(m);
      so.table_T_model = placed[n_placed].table_T_model;
      // Albedos spread over a range so that objects differ in grey level.
      so.albedo = params.background == Background::kDark
                      ? 0.5f + 0.4f * (static_cast<float>(i) + rng.Uniform()) / params.n_objects
                      : 0.12f + 0.28f * (static_cast<float>(i) + rng.Uniform()) / params.n_objects;
      (void)out.scene.objects.push_back(so);
      out.left_T_model[n_placed] = rig.left_T_table * so.table_T_model;
      ++n_placed;
    }
    if (n_placed < params.n_objects) continue;
    int overlaps = 0;
    for (int a = 0; a < n_placed; ++a) {
      for (int b = a + 1; b < n_placed; ++b) {
        overlaps += Separation(placed[a].silhouette[0], placed[b].silhouette[0]) < -2.0f;
      }
    }
    if (overlaps < min_overlaps) continue;
    return out;
  }
  return Status::Error(StatusCode::kResourceExhausted,
                       "scene: could not place %d objects (occlusion level %d) in view at %.0f mm "
                       "after %d attempts; use fewer objects or a larger distance",
                       params.n_objects, static_cast<int>(params.occlusion),
                       params.camera_distance_mm, kSceneTries);
}

}  // namespace sh::render
