#include "tools/miss_causes.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "recog/stereo/epipolar.hpp"
#include "recog/verify/verify.hpp"
#include "recog/verify/visible_edges.hpp"
#include "tools/eval/rendered_eval.hpp"
#include "tools/eval/truth_pose_fit.hpp"

namespace sh::tools {
namespace {

// Tolerances of the feature chain: a detected 2-D feature within these of the projected truth,
// a 3-D feature within these of the posed model.
constexpr float kCornerPx = 3.0f, kLinePx = 2.5f, kLineAngleDeg = 4.0f;
constexpr float kPointMm = 3.0f, kLineMm = 3.0f, kLine3dAngleDeg = 6.0f;

float Distance2d(const Eigen::Vector2f& p, const Segment2D& s) {
  const Eigen::Vector2f a(s.x0, s.y0), b(s.x1, s.y1);
  const Eigen::Vector2f d = b - a;
  const float t = std::clamp((p - a).dot(d) / std::max(d.squaredNorm(), 1e-9f), 0.0f, 1.0f);
  return (a + t * d - p).norm();
}

// Counts, for the object at its true pose, which of its visible corners and edges the 2-D
// detectors and stereo found (MissRecord's chain counts).
void TraceFeatureChain(const Pipeline& pipeline, const PosedModel& object,
                       const PosedModel* occluders, size_t n_occluders, MissRecord* record) {
  const StereoCalibration& calib = pipeline.calibration();
  const ViewCamera views[2] = {LeftView(calib), RightView(calib)};
  const ImageFeatures* features[2] = {&pipeline.left_features(), &pipeline.right_features()};
  const Model& model = *object.model;
  bool edge_seen[2][kMaxModelEdges] = {}, corner_seen[2][kMaxModelCorners] = {};
  bool edge_found[2][kMaxModelEdges] = {}, corner_found[2][kMaxModelCorners] = {};
  const float cos_2d = std::cos(kLineAngleDeg * 3.14159265f / 180.0f);
  for (int v = 0; v < 2; ++v) {
    VisibleEdgeSet visible;
    if (!ComputeVisibleEdges(views[v], object, occluders, n_occluders, 1.0f, 1.0f, &visible).ok()) {
      return;
    }
    const double max_r2 = MaxImageRadius2(views[v].intrinsics);
    for (int k = 0; k < visible.n_edges; ++k) {
      const VisibleEdge& ve = visible.edges[k];
      int n_visible = 0;
      for (int r = 0; r < ve.n_runs; ++r) n_visible += ve.runs[r].end - ve.runs[r].first;
      const int a = model.edges[ve.edge].a, b = model.edges[ve.edge].b;
      if (ve.n_samples > 0 && IsSampleVisible(ve, 0)) corner_seen[v][a] = true;
      if (ve.n_samples > 0 && IsSampleVisible(ve, ve.n_samples - 1)) corner_seen[v][b] = true;
      if (2 * n_visible < ve.n_samples || ve.n_samples < 8) continue;
      edge_seen[v][ve.edge] = true;
      // Found when a detected segment runs along the visible edge: direction within
      // kLineAngleDeg, and the middle and both quarter points within kLinePx of a segment.
      Eigen::Vector2f p[3];
      bool inside = true;
      for (int q = 0; q < 3; ++q) {
        const float s = 0.25f * float(q + 1);
        inside = inside &&
                 ProjectInView(views[v].intrinsics, max_r2, PointAtImageFraction(ve, s), &p[q]);
      }
      if (!inside) continue;
      const Eigen::Vector2f dir = (p[2] - p[0]).normalized();
      for (const Line2D& line : features[v]->lines) {
        if (std::fabs(dir.dot(Eigen::Vector2f(line.dir_x, line.dir_y))) < cos_2d) continue;
        int near = 0;
        for (const Eigen::Vector2f& x : p) {
          float best = 1e9f;
          for (const Segment2D& seg : line.segments) best = std::min(best, Distance2d(x, seg));
          near += best <= kLinePx;
        }
        if (near >= 2) {
          edge_found[v][ve.edge] = true;
          break;
        }
      }
    }
    for (int c = 0; c < model.n_corners; ++c) {
      if (!corner_seen[v][c]) continue;
      Eigen::Vector2f px;
      const Eigen::Vector3f x_cam = views[v].cam_T_left * (object.cam_T_model * model.corner(c));
      if (!ProjectInView(views[v].intrinsics, max_r2, x_cam, &px)) continue;
      for (const Corner2D& corner : features[v]->corners) {
        if ((Eigen::Vector2f(corner.x_px, corner.y_px) - px).norm() <= kCornerPx) {
          corner_found[v][c] = true;
          break;
        }
      }
    }
  }
  const Scene& scene = pipeline.scene();
  const float cos_3d = std::cos(kLine3dAngleDeg * 3.14159265f / 180.0f);
  for (int e = 0; e < model.n_edges; ++e) {
    if (!edge_seen[0][e] || !edge_seen[1][e]) continue;
    ++record->edges_visible;
    record->edges_2d[0] += edge_found[0][e];
    record->edges_2d[1] += edge_found[1][e];
    const Eigen::Vector3f a = object.cam_T_model * model.corner(model.edges[e].a);
    const Eigen::Vector3f b = object.cam_T_model * model.corner(model.edges[e].b);
    const Eigen::Vector3f d = (b - a).normalized();
    bool found3 = false;
    for (const SceneLine& l : scene.lines) {
      if (std::fabs(l.direction().dot(d)) < cos_3d) continue;
      const Eigen::Vector3f mid = 0.5f * (l.a_mm + l.b_mm) - a;
      if ((mid - mid.dot(d) * d).norm() <= kLineMm) {
        ++record->edges_3d;
        found3 = true;
        break;
      }
    }
    if (edge_found[0][e] && edge_found[1][e]) {
      ++record->edges_2d_both;
      // Found in both images but not triangulated: was the pair too close to the epipolar
      // direction for line stereo (its interpretation planes nearly parallel)?
      if (!found3) {
        ++record->edges_lost_stereo;
        if (InterpretationPlaneAngleDeg(calib, a.cast<double>(), b.cast<double>()) <
            pipeline.config().stereo.min_plane_angle_deg) {
          ++record->edges_lost_epipolar;
        }
      }
    }
  }
  for (int c = 0; c < model.n_corners; ++c) {
    if (!corner_seen[0][c] || !corner_seen[1][c]) continue;
    ++record->corners_visible;
    record->corners_2d[0] += corner_found[0][c];
    record->corners_2d[1] += corner_found[1][c];
    const Eigen::Vector3f x = object.cam_T_model * model.corner(c);
    for (const ScenePoint& p : scene.points) {
      if ((p.p_mm - x).norm() <= kPointMm) {
        ++record->corners_3d;
        break;
      }
    }
  }
}

// Fills the search fields of `record` (see MissRecord). `search` holds the prepared scene.
void TraceSearch(Recognizer& search, const Scene& scene, const PosedModel& object, int model_id,
                 MissRecord* record) {
  if (!UsesLinePoint(search.table().hash_function())) return;
  const Model& model = *object.model;
  auto on_object_point = [&](const Eigen::Vector3f& p) {
    for (int c = 0; c < model.n_corners; ++c) {
      if ((object.cam_T_model * model.corner(c) - p).norm() <= kPointMm) return true;
    }
    return false;
  };
  const float cos_3d = std::cos(kLine3dAngleDeg * 3.14159265f / 180.0f);
  auto on_object_line = [&](const SceneLine& l) {
    for (int e = 0; e < model.n_edges; ++e) {
      const Eigen::Vector3f a = object.cam_T_model * model.corner(model.edges[e].a);
      const Eigen::Vector3f b = object.cam_T_model * model.corner(model.edges[e].b);
      const Eigen::Vector3f d = (b - a).normalized();
      if (std::fabs(l.direction().dot(d)) < cos_3d) continue;
      const Eigen::Vector3f mid = 0.5f * (l.a_mm + l.b_mm) - a;
      if ((mid - mid.dot(d) * d).norm() <= kLineMm) return true;
    }
    return false;
  };
  record->candidates = int(search.CandidateCount());
  Vector<Hypothesis, kMaxHypothesesPerBasis> hypotheses;
  for (uint32_t i = 0; i < search.CandidateCount(); ++i) {
    const SceneBasis& b = search.Candidate(i);
    if (!on_object_line(scene.lines[b.f[0]]) || !on_object_point(scene.points[b.f[1]].p_mm)) {
      continue;
    }
    ++record->own_bases;
    if (record->first_own_rank < 0) record->first_own_rank = int(i);
    search.VoteForBasis(b, hypotheses);
    for (const Hypothesis& h : hypotheses) {
      if (h.model != model_id) continue;
      const float dt = (h.cam_T_model.t_mm - object.cam_T_model.t_mm).norm();
      const float dr = SymmetricRotationErrorDeg(model, h.cam_T_model.R, object.cam_T_model.R);
      if (dt <= 10.0f && dr <= 10.0f) {
        ++record->good_bases;
        if (record->first_good_rank < 0) record->first_good_rank = int(i);
        break;
      }
    }
  }
}

// Fills the trace fields of `record` (see MissRecord).
void SummariseTrace(const SearchTrace& trace, const std::vector<Model>& models,
                    const TruthObject& truth, MissRecord* record) {
  const Model& model = models[truth.model];
  auto error = [&](const RigidTransform& pose, float* dt, float* dr) {
    *dt = (pose.t_mm - truth.cam_T_model.t_mm).norm();
    *dr = SymmetricRotationErrorDeg(model, pose.R, truth.cam_T_model.R);
  };
  for (const SearchTrace::Step& step : trace.steps) {
    if (step.hypothesis.model != truth.model) continue;
    float dt = 0, dr = 0;
    error(step.hypothesis.cam_T_model, &dt, &dr);
    if (dt > 10.0f || dr > 10.0f) continue;
    ++record->near_hypotheses;
    error(step.candidate.cam_T_model, &dt, &dr);
    record->refined_close += dt <= 5.0f && dr <= 5.0f;
    switch (step.outcome) {
      case SearchObserver::Outcome::kTooClose:
        ++record->too_close;
        break;
      case SearchObserver::Outcome::kRejected:
        ++record->rejected;
        break;
      case SearchObserver::Outcome::kVerified:
        ++record->verified;
        for (const auto& [number, object] : trace.accepted) {
          if (number == step.basis_number) record->lost_to = models[object.model].name;
        }
        break;
    }
    if (step.outcome != SearchObserver::Outcome::kTooClose &&
        step.candidate.verify_score[0] + step.candidate.verify_score[1] >
            record->best_verify[0] + record->best_verify[1]) {
      record->best_verify[0] = step.candidate.verify_score[0];
      record->best_verify[1] = step.candidate.verify_score[1];
    }
  }
}

}  // namespace

void ExplainMisses(const std::vector<Model>& models, const std::vector<TruthObject>& truth,
                   const PipelineResult& result, const Pipeline& pipeline, const char* label,
                   bool verbose, MissCauses* causes, float max_t_mm, float max_r_deg,
                   std::vector<MissRecord>* records, Recognizer* search, const SearchTrace* trace) {
  const std::vector<RecognizedPose> found = PosesOf(result);
  const MatchCounts matched = MatchToTruth(models, truth, found, max_t_mm, max_r_deg);
  bool prepared = false;
  for (size_t i = 0; i < truth.size(); ++i) {
    if (matched.truth_found[i]) continue;
    const Model& model = models[truth[i].model];
    PosedModel occluders[kMaxOccluders];
    size_t n_occluders = 0;
    for (size_t j = 0; j < truth.size() && n_occluders < kMaxOccluders; ++j) {
      if (j != i) occluders[n_occluders++] = {&models[truth[j].model], truth[j].cam_T_model};
    }
    if (pipeline.models().is_shape(static_cast<uint32_t>(truth[i].model))) {
      // A colour part: refine from the true pose and verify there, the other parts hiding it.
      for (size_t k = 0; k < n_occluders; ++k) {
        const int id = pipeline.models().Find(occluders[k].model->name);
        if (id >= 0) occluders[k].model = &pipeline.models().model(static_cast<uint32_t>(id));
      }
      PosedModel object{&pipeline.models().model(static_cast<uint32_t>(truth[i].model)),
                        truth[i].cam_T_model};
      ShapeRecognizer::Assessment a;
      const bool ok = pipeline.shape() != nullptr &&
                      pipeline.shape()->Assess(&object, occluders, n_occluders, &a).ok() &&
                      a.accepted;
      MissRecord record;
      record.truth_index = i;
      record.verify_score[0] = a.edge_score[0];
      record.verify_score[1] = a.edge_score[1];
      if (ok) {
        ++causes->not_searched;
        record.cause = "not_searched";
      } else {
        ++causes->no_edges;
        record.cause = "no_edges";
      }
      if (records != nullptr) records->push_back(record);
      if (verbose) {
        std::printf(
            "  %s: missed %s; from its true pose: edges confirmed %.2f %.2f, background %.2f "
            "%.2f (%s)\n",
            label, model.name, a.edge_score[0], a.edge_score[1], a.background_share[0],
            a.background_share[1], ok ? "verified: not reached" : "rejected");
      }
      continue;
    }
    const ConstEdgeMapView left{pipeline.left_features().edges.edge,
                                pipeline.left_features().edges.orientation};
    const ConstEdgeMapView right{pipeline.right_features().edges.edge,
                                 pipeline.right_features().edges.orientation};
    const Result<VerifyResult> v = VerifyHypothesis(
        pipeline.calibration(), left, right, {&model, truth[i].cam_T_model}, occluders, n_occluders,
        pipeline.config().verify, pipeline.grey_evidence(0), pipeline.grey_evidence(1));
    const TruthPoseFit fit = FitFromTruePose(model, truth[i].cam_T_model, pipeline.scene(),
                                             pipeline.config().recognizer);
    const bool verifiable = v.ok() && v->accepted;
    MissRecord record;
    record.truth_index = i;
    record.verify_score[0] = v.ok() ? v->score_left : 0.0f;
    record.verify_score[1] = v.ok() ? v->score_right : 0.0f;
    record.support = fit.support;
    if (!verifiable) {
      ++causes->no_edges;
      record.cause = "no_edges";
    } else if (fit.support < 0.3f) {
      ++causes->no_3d;
      record.cause = "no_3d";
    } else {
      ++causes->not_searched;
      record.cause = "not_searched";
    }
    TraceFeatureChain(pipeline, {&model, truth[i].cam_T_model}, occluders, n_occluders, &record);
    if (search != nullptr) {
      if (!prepared) search->PrepareScene(pipeline.scene());
      prepared = true;
      TraceSearch(*search, pipeline.scene(), {&model, truth[i].cam_T_model}, truth[i].model,
                  &record);
    }
    if (trace != nullptr) SummariseTrace(*trace, models, truth[i], &record);
    if (records != nullptr) records->push_back(record);
    if (verbose) {
      std::printf(
          "  %s: missed %s; at its true pose: image verification %.2f %.2f (%s), 3-D "
          "support %.2f (%d corners, %d edges); edges visible %d, 2-D %d / %d, 3-D %d; corners "
          "visible %d, 2-D %d / %d, 3-D %d\n"
          "    edges found in both images %d, not triangulated %d, of them %d near the epipolar "
          "direction (interpretation planes under %.1f deg apart)\n",
          label, model.name, record.verify_score[0], record.verify_score[1],
          verifiable ? "accepted" : (v.ok() ? VerifyReasonName(v->reason) : "error"), fit.support,
          fit.matched_points, fit.matched_lines, record.edges_visible, record.edges_2d[0],
          record.edges_2d[1], record.edges_3d, record.corners_visible, record.corners_2d[0],
          record.corners_2d[1], record.corners_3d, record.edges_2d_both, record.edges_lost_stereo,
          record.edges_lost_epipolar, pipeline.config().stereo.min_plane_angle_deg);
      if (search != nullptr) {
        std::printf(
            "    search: %d own scene bases of %d (first at rank %d), %d vote the true model near "
            "its pose (first at rank %d)\n",
            record.own_bases, record.candidates, record.first_own_rank, record.good_bases,
            record.first_good_rank);
      }
      if (trace != nullptr) {
        std::printf(
            "    tried: %d hypotheses near the truth, %d refined within 5 mm / 5 deg; %d too close "
            "to an accepted object, %d rejected, %d verified%s%s; best verify %.2f %.2f\n",
            record.near_hypotheses, record.refined_close, record.too_close, record.rejected,
            record.verified, record.lost_to[0] ? " but lost to a " : "", record.lost_to,
            record.best_verify[0], record.best_verify[1]);
      }
    }
  }
}

}  // namespace sh::tools
