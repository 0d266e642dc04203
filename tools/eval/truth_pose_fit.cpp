#include "tools/eval/truth_pose_fit.hpp"

#include <cstring>

#include "recog/hashing/scene_grid.hpp"
#include "tools/eval/synthetic_scene.hpp"

namespace sh {

TruthPoseFit FitFromTruePose(const Model& model, const RigidTransform& true_cam_T_model,
                             const Scene& scene, const RecognizerConfig& config) {
  static uint8_t point_active[kMaxScenePoints], line_active[kMaxSceneLines];
  static Eigen::Vector3f positions[kMaxScenePoints];
  static SceneGrid grid;
  std::memset(point_active, 1, sizeof(point_active));
  std::memset(line_active, 1, sizeof(line_active));
  const int n = int(scene.points.size());
  for (int i = 0; i < n; ++i) positions[i] = scene.points[i].p_mm;
  grid.Build(positions, n, 10.0f);

  RefineInput in;
  in.model = &model;
  in.scene = &scene;
  in.point_active = point_active;
  in.line_active = line_active;
  in.point_grid = &grid;
  in.sigma_point_mm = config.sigma_point_mm;
  in.sigma_line_mm = config.sigma_line_mm;
  const RefineResult refined = RefinePose(in, true_cam_T_model, config.refine);
  Correspondences tight;
  SelectCorrespondences(in, refined.cam_T_model, config.support_gate_sigmas * config.sigma_point_mm,
                        &tight);
  TruthPoseFit fit;
  fit.matched_points = tight.matched_points;
  fit.matched_lines = tight.matched_lines;
  fit.support = 0.5f * (float(tight.matched_points) / float(model.n_corners) +
                        float(tight.matched_lines) / float(model.n_edges));
  fit.t_err_mm = (refined.cam_T_model.t_mm - true_cam_T_model.t_mm).norm();
  fit.r_err_deg = SymmetricRotationErrorDeg(model, refined.cam_T_model.R, true_cam_T_model.R);
  return fit;
}

}  // namespace sh
