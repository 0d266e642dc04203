#include "tools/eval/synthetic_scene.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

namespace sh {
namespace {

// splitmix64: identical streams on every platform and library. Several draws in one call's
// arguments would be taken in the compiler's order (GCC takes them last to first on x86-64 and
// first to last on AArch64), so vectors are drawn one component a statement, last to first.
class Rng {
 public:
  explicit Rng(uint64_t seed) : state_(seed) {}
  uint64_t Next() {
    uint64_t z = (state_ += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
  }
  float Uniform() { return float(Next() >> 40) * (1.0f / 16777216.0f); }  // [0, 1)
  float Uniform(float lo, float hi) { return lo + (hi - lo) * Uniform(); }
  int Int(int lo, int hi) { return lo + int(Next() % uint64_t(hi - lo + 1)); }  // [lo, hi]
  float Gaussian() {                                                            // Box-Muller
    const float u1 = std::max(Uniform(), 1e-7f), u2 = Uniform();
    return std::sqrt(-2.0f * std::log(u1)) * std::cos(6.2831853f * u2);
  }
  Eigen::Vector3f Gaussian3(float sigma) {
    Eigen::Vector3f v;
    for (int k = 2; k >= 0; --k) v[k] = Gaussian();
    return sigma * v;
  }
  Eigen::Vector3f UnitVector() {
    for (;;) {
      Eigen::Vector3f v;
      for (int k = 2; k >= 0; --k) v[k] = Uniform(-1, 1);
      const float n = v.norm();
      if (n > 0.1f && n <= 1.0f) return v / n;
    }
  }
  Eigen::Matrix3f Rotation() {  // uniform on SO(3) via a uniform unit quaternion
    Eigen::Vector4f q;
    do {
      for (int k = 3; k >= 0; --k) q[k] = Gaussian();
    } while (q.norm() < 1e-3f);
    q.normalize();
    return Eigen::Quaternionf(q[0], q[1], q[2], q[3]).toRotationMatrix();
  }

 private:
  uint64_t state_;
};

float ModelRadius(const Model& m) {
  float r = 0;
  for (int i = 0; i < m.n_corners; ++i) r = std::max(r, m.corner(i).norm());
  return r;
}

struct Builder {
  Scene& scene;
  uint16_t next_left_point = 0, next_right_point = 0, next_left_line = 0, next_right_line = 0;

  bool AddPoint(const Eigen::Vector3f& p, uint16_t left_id) {
    ScenePoint sp;
    sp.p_mm = p;
    sp.source = {left_id, next_right_point++};
    sp.quality = 1.0f;
    return scene.points.push_back(sp);
  }
  bool AddLine(const Eigen::Vector3f& a, const Eigen::Vector3f& b, uint16_t left_id) {
    SceneLine l;
    l.a_mm = a;
    l.b_mm = b;
    l.source = {left_id, next_right_line++};
    l.quality = (b - a).norm();
    return scene.lines.push_back(l);
  }
};

// Adds a model's features at a pose: keep each with probability keep; noise sigma; segments
// shortened at random ends, as partly detected edges are. Returns false when the scene is full.
void AddModelFeatures(const Model& m, const RigidTransform& cam_T_model, float keep, float sigma,
                      Rng& rng, Builder& b) {
  for (int i = 0; i < m.n_corners; ++i) {
    if (rng.Uniform() >= keep) continue;
    (void)b.AddPoint(cam_T_model * m.corner(i) + rng.Gaussian3(sigma), b.next_left_point++);
  }
  for (int e = 0; e < m.n_edges; ++e) {
    if (rng.Uniform() >= keep) continue;
    const Eigen::Vector3f a = cam_T_model * m.corner(m.edges[e].a);
    const Eigen::Vector3f c = cam_T_model * m.corner(m.edges[e].b);
    const float t0 = rng.Uniform(0.0f, 0.2f), t1 = rng.Uniform(0.8f, 1.0f);
    // Both end points get the same perpendicular noise model as corners (drawn one a statement,
    // end first, see Rng).
    const Eigen::Vector3f noise_end = rng.Gaussian3(sigma);
    const Eigen::Vector3f noise_start = rng.Gaussian3(sigma);
    (void)b.AddLine(a + t0 * (c - a) + noise_start, a + t1 * (c - a) + noise_end,
                    b.next_left_line++);
  }
}

}  // namespace

void GenerateSyntheticScene(const std::vector<Model>& models, const SyntheticSceneParams& params,
                            uint64_t seed, SyntheticScene* out) {
  Rng rng(seed * 0x2545F4914F6CDD1Dull + 1);
  out->scene.clear();
  out->truth.clear();
  Builder b{out->scene};
  std::vector<int> enabled;
  for (int m = 0; m < int(models.size()); ++m) {
    if ((params.model_mask >> m) & 1u) enabled.push_back(m);
  }
  const Eigen::Vector3f lo = params.volume_min_mm, hi = params.volume_max_mm;
  // One draw a statement, z to x (see Rng).
  auto uniform_in_volume = [&]() {
    const float z = rng.Uniform(lo.z(), hi.z());
    const float y = rng.Uniform(lo.y(), hi.y());
    const float x = rng.Uniform(lo.x(), hi.x());
    return Eigen::Vector3f(x, y, z);
  };

  // Objects: random model, random rotation, centre in the volume, no two overlapping.
  const int n_objects = rng.Int(params.min_objects, params.max_objects);
  const float sigma = rng.Uniform(params.noise_min_mm, params.noise_max_mm);
  const float keep = 1.0f - rng.Uniform(params.missing_min, params.missing_max);
  for (int attempt = 0; int(out->truth.size()) < n_objects && attempt < 1000; ++attempt) {
    TruthObject t;
    t.model = enabled[rng.Int(0, int(enabled.size()) - 1)];
    t.cam_T_model.R = rng.Rotation();
    t.cam_T_model.t_mm = uniform_in_volume();
    const float r = ModelRadius(models[t.model]);
    bool clear = true;
    for (const TruthObject& o : out->truth) {
      clear &= (o.cam_T_model.t_mm - t.cam_T_model.t_mm).norm() > r + ModelRadius(models[o.model]);
    }
    if (clear) out->truth.push_back(t);
  }
  for (const TruthObject& t : out->truth)
    AddModelFeatures(models[t.model], t.cam_T_model, keep, sigma, rng, b);

  // Clutter up to the requested total.
  const int object_features = int(out->scene.points.size() + out->scene.lines.size());
  const int clutter = std::max(0, params.total_features - object_features);
  const int structured = int(float(clutter) * params.structured_fraction);
  int added = 0;
  while (added < structured) {
    const int before = int(out->scene.points.size() + out->scene.lines.size());
    if (rng.Uniform() < 0.5f) {
      // A fragment of a model outline at a random pose (about a quarter of its features).
      const Model& m = models[enabled[rng.Int(0, int(enabled.size()) - 1)]];
      RigidTransform pose{rng.Rotation(), uniform_in_volume()};
      AddModelFeatures(m, pose, 0.25f, sigma, rng, b);
    } else if (!out->scene.points.empty()) {
      // A false stereo match: a real feature displaced along the viewing ray, sharing its left
      // image feature.
      if (rng.Uniform() < 0.5f) {
        const ScenePoint& p = out->scene.points[rng.Int(0, int(out->scene.points.size()) - 1)];
        const Eigen::Vector3f shifted = p.p_mm * (1.0f + rng.Uniform(-0.06f, 0.06f));
        (void)b.AddPoint(shifted, p.source.left);
      } else if (!out->scene.lines.empty()) {
        const SceneLine& l = out->scene.lines[rng.Int(0, int(out->scene.lines.size()) - 1)];
        const float s = 1.0f + rng.Uniform(-0.06f, 0.06f);
        (void)b.AddLine(l.a_mm * s, l.b_mm * s, l.source.left);
      }
    }
    const int after = int(out->scene.points.size() + out->scene.lines.size());
    if (after == before && out->scene.points.full()) break;
    added += std::max(1, after - before);
  }
  for (int i = added; i < clutter; ++i) {
    if (rng.Uniform() < 0.5f) {
      if (!b.AddPoint(uniform_in_volume(), b.next_left_point++)) break;
    } else {
      const Eigen::Vector3f a = uniform_in_volume();
      const Eigen::Vector3f direction = rng.UnitVector();
      const float length_mm = rng.Uniform(10.0f, 60.0f);
      const Eigen::Vector3f c = a + length_mm * direction;
      if (!b.AddLine(a, c, b.next_left_line++)) break;
    }
  }
  // Stereo emits features in image order, not object by object: shuffle.
  auto& pts = out->scene.points;
  for (size_t i = pts.size(); i > 1; --i) std::swap(pts[i - 1], pts[rng.Next() % i]);
  auto& lines = out->scene.lines;
  for (size_t i = lines.size(); i > 1; --i) std::swap(lines[i - 1], lines[rng.Next() % i]);
}

float SymmetricRotationErrorDeg(const Model& model, const Eigen::Matrix3f& R_estimate,
                                const Eigen::Matrix3f& R_truth) {
  float best = 180.0f;
  const int n = std::max<int>(1, model.n_symmetries);
  for (int k = 0; k < n; ++k) {
    const Eigen::Matrix3f g = model.n_symmetries ? model.symmetry(k) : Eigen::Matrix3f::Identity();
    best = std::min(best, RotationAngleDeg(R_estimate.transpose() * R_truth * g));
  }
  return best;
}

MatchCounts MatchToTruth(const std::vector<Model>& models, const std::vector<TruthObject>& truth,
                         const std::vector<RecognizedPose>& found, float max_translation_mm,
                         float max_rotation_deg) {
  MatchCounts c;
  std::vector<bool> used(truth.size(), false);
  for (const RecognizedPose& f : found) {
    int match = -1;
    float t_err = 0, r_err = 0;
    for (size_t i = 0; i < truth.size() && match < 0; ++i) {
      if (used[i] || truth[i].model != f.model) continue;
      t_err = (truth[i].cam_T_model.t_mm - f.cam_T_model.t_mm).norm();
      r_err = SymmetricRotationErrorDeg(models[f.model], f.cam_T_model.R, truth[i].cam_T_model.R);
      if (t_err <= max_translation_mm && r_err <= max_rotation_deg) match = int(i);
    }
    if (match < 0) {
      ++c.false_alarms;
      continue;
    }
    used[match] = true;
    ++c.correct;
    c.translation_errors_mm.push_back(t_err);
    c.rotation_errors_deg.push_back(r_err);
  }
  for (bool u : used) c.missed += !u;
  c.truth_found = used;
  return c;
}

}  // namespace sh
