// Shared pieces of the monocular tests: the reference models, aspect tables built from them,
// the thesis camera, and ideal image features of posed models (exact projections).
#pragma once

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include "recog/mono/aspect.hpp"
#include "recog/mono/aspect_voter.hpp"
#include "recog/mono/mono_pose.hpp"
#include "recog/mono/resting_pose.hpp"
#include "recog/verify/visible_edges.hpp"
#include "tables/aspect_view.hpp"
#include "tables/model_files.hpp"
#include "tools/tablegen/aspect_builder.hpp"
#include "tools/tablegen/model_symmetry.hpp"

namespace sh::testing {

// The six reference models with their symmetry groups.
inline const std::vector<Model>& ReferenceModels() {
  static const std::vector<Model> models = [] {
    std::vector<Model> m;
    const Status s = LoadModelFolder(STEREOHASH_MODELS_DIR, &m);
    EXPECT_TRUE(s.ok()) << s.message();
    for (Model& model : m) StoreSymmetries(model, FindSymmetries(model));
    return m;
  }();
  return models;
}

inline const Model& ReferenceModel(const char* name) {
  for (const Model& m : ReferenceModels()) {
    if (std::strcmp(m.name, name) == 0) return m;
  }
  ADD_FAILURE() << "no model " << name;
  return ReferenceModels().front();
}

// An aspect table blob kept 8-byte aligned, with its view.
struct BuiltAspectTable {
  std::vector<uint64_t> storage;
  size_t size = 0;
  AspectTableView view;
  AspectBuildReport report;
};

inline std::unique_ptr<BuiltAspectTable> BuildTable(const std::vector<Model>& models,
                                                    const AspectBuildOptions& options) {
  auto t = std::make_unique<BuiltAspectTable>();
  Result<std::vector<uint8_t>> blob = BuildAspectBlob(models, options, &t->report);
  EXPECT_TRUE(blob.ok()) << blob.status().message();
  if (!blob.ok()) return t;
  t->size = blob->size();
  t->storage.assign((blob->size() + 7) / 8, 0);
  std::memcpy(t->storage.data(), blob->data(), blob->size());
  Result<AspectTableView> view = AspectTableView::Open(t->storage.data(), t->size);
  EXPECT_TRUE(view.ok()) << view.status().message();
  if (view.ok()) t->view = *view;
  return t;
}

// A voter set up on the aspect table of one model, built without refinement.
struct ModelVoter {
  std::unique_ptr<BuiltAspectTable> table;
  std::unique_ptr<AspectVoter> voter;
};

inline ModelVoter VoterOf(const Model& model, const VoterConfig& config = {}) {
  ModelVoter v;
  AspectBuildOptions options;
  options.refine = false;
  v.table = BuildTable({model}, options);
  EXPECT_TRUE(v.table->view.valid());
  v.voter = std::make_unique<AspectVoter>();
  EXPECT_TRUE(v.voter->Init(v.table->view, config).ok());
  return v;
}

// The thesis camera: 756 x 581 px, f = 1136.4 px, no distortion.
inline CameraIntrinsics ThesisCamera() {
  CameraIntrinsics c;
  c.width = 756;
  c.height = 581;
  c.fx = c.fy = 1136.36363636;
  c.cx = 377.5;
  c.cy = 290.0;
  return c;
}

inline RigidTransform PoseFromAxisAngle(const Eigen::Vector3f& axis, float angle_deg,
                                        const Eigen::Vector3f& t_mm) {
  RigidTransform T;
  T.R = Eigen::AngleAxisf(angle_deg * 3.14159265f / 180.0f, axis.normalized()).toRotationMatrix();
  T.t_mm = t_mm;
  return T;
}

// Exact image features of a posed model: its 2-D corners and visible edge pieces, in
// distorted pixels (for the pose fit) and ideal pixels (for the vote).
struct ProjectedFeatures {
  std::vector<PoseCorner> corners;
  std::vector<PoseLine> lines;
  std::vector<ScenePoint2d> ideal_points;
  std::vector<SceneLine2d> ideal_lines;
  std::vector<int> corner_model_index;  // model corner of each image corner
};

inline ProjectedFeatures ProjectModel(const CameraIntrinsics& cam, const Model& model,
                                      const RigidTransform& cam_T_model) {
  ProjectedFeatures out;
  const ViewCamera view{cam, RigidTransform::Identity()};
  VisibleEdgeSet visible;
  const Status s =
      ComputeVisibleEdges(view, {&model, cam_T_model}, nullptr, 0, 0.5f, 1.0f, &visible);
  EXPECT_TRUE(s.ok()) << s.message();
  const double f = std::sqrt(cam.fx * cam.fy);
  Eigen::Vector2f px[kMaxModelCorners];
  for (int i = 0; i < model.n_corners; ++i) {
    Eigen::Vector2d p;
    EXPECT_TRUE(ProjectToPixel(cam, (cam_T_model * model.corner(i)).cast<double>(), &p));
    px[i] = p.cast<float>();
  }
  const CornerMask corners = VisibleCorners2d(model, visible, px, 20.0f);
  for (int i = 0; i < model.n_corners; ++i) {
    if (!corners.test(static_cast<size_t>(i))) continue;
    out.corners.push_back({px[i]});
    const Eigen::Vector2d n = UndistortPixel(cam, px[i].cast<double>());
    out.ideal_points.push_back({(f * n).cast<float>()});
    out.corner_model_index.push_back(i);
  }
  for (int k = 0; k < visible.n_edges; ++k) {
    const VisibleEdge& ve = visible.edges[k];
    for (int r = 0; r < ve.n_runs; ++r) {
      const float s0 = float(ve.runs[r].first) / ve.n_samples;
      const float s1 = float(ve.runs[r].end) / ve.n_samples;
      Eigen::Vector2d a, b;
      EXPECT_TRUE(ProjectToPixel(cam, PointAtImageFraction(ve, s0).cast<double>(), &a));
      EXPECT_TRUE(ProjectToPixel(cam, PointAtImageFraction(ve, s1).cast<double>(), &b));
      if ((b - a).norm() < 10.0) continue;
      PoseLine l;
      l.dir = (b - a).normalized().cast<float>();
      l.normal = {-l.dir.y(), l.dir.x()};
      l.rho = l.normal.dot(a.cast<float>());
      l.t0 = l.dir.dot(a.cast<float>());
      l.t1 = l.dir.dot(b.cast<float>());
      out.lines.push_back(l);
      const Eigen::Vector2d ia = f * UndistortPixel(cam, a), ib = f * UndistortPixel(cam, b);
      SceneLine2d il;
      il.point = ia.cast<float>();
      il.dir = (ib - ia).normalized().cast<float>();
      il.t0 = 0;
      il.t1 = static_cast<float>((ib - ia).norm());
      out.ideal_lines.push_back(il);
    }
  }
  return out;
}

// The thesis set's table: camera 290 mm above it, looking down 51.5 degrees from the normal.
inline TablePlane ThesisTable() {
  TablePlane t;
  t.cam_T_table.R << 0.986393923832f, -0.164398987305f, 0.0f, -0.102274478266f, -0.613646869597f,
      -0.782928764658f, 0.128712696042f, 0.772276176252f, -0.622111364203f;
  t.cam_T_table.t_mm = {4.93196961916f, 18.4094060879f, 442.986195545f};
  return t;
}

// Rotation error modulo the model's symmetries, degrees.
inline float RotationErrorDeg(const Model& m, const Eigen::Matrix3f& truth,
                              const Eigen::Matrix3f& est) {
  float best = 180.0f;
  for (int k = 0; k < m.n_symmetries; ++k) {
    best = std::min(best, RotationAngleDeg((truth * m.symmetry(k)).transpose() * est));
  }
  return best;
}

// One vote for the scene basis (i, j) of these features.
inline int VotePair(AspectVoter& voter, const std::vector<ScenePoint2d>& points,
                    const std::vector<SceneLine2d>& lines, int i, int j, float threshold,
                    AspectHypothesis* out, int max_out, VoteCounts* counts = nullptr) {
  VoteScene scene;
  scene.points = points.data();
  scene.n_points = static_cast<int>(points.size());
  scene.lines = lines.data();
  scene.n_lines = static_cast<int>(lines.size());
  VoteRequest request;
  request.frame = SimilarityFrame(points[i].xy, points[j].xy);
  request.exclude[0] = i;
  request.exclude[1] = j;
  request.n_exclude = 2;
  request.threshold = threshold;
  return voter.Vote(scene, request, out, max_out, counts);
}

}  // namespace sh::testing
