#include "recog/verify/inside_object.hpp"

namespace sh {

bool CentreInside(const Model& model, const RigidTransform& cam_T_model, const PosedModel& other) {
  if (model.n_corners == 0 || other.model == nullptr || other.model->n_corners == 0) return false;
  Eigen::Vector3f centroid_mm = Eigen::Vector3f::Zero();
  for (int i = 0; i < model.n_corners; ++i) centroid_mm += model.corner(i);
  centroid_mm /= static_cast<float>(model.n_corners);
  const Eigen::Vector3f cam_p_mm = cam_T_model.R * centroid_mm + cam_T_model.t_mm;
  // The centroid in the other object's frame, against its corners' box.
  const RigidTransform& cam_T_other = other.cam_T_model;
  const Eigen::Vector3f p_mm = cam_T_other.R.transpose() * (cam_p_mm - cam_T_other.t_mm);
  const Model& o = *other.model;
  Eigen::Vector3f lo = o.corner(0), hi = o.corner(0);
  for (int i = 1; i < o.n_corners; ++i) {
    lo = lo.cwiseMin(o.corner(i));
    hi = hi.cwiseMax(o.corner(i));
  }
  return (p_mm.array() >= lo.array()).all() && (p_mm.array() <= hi.array()).all();
}

bool Interpenetrate(const PosedModel& a, const PosedModel& b) {
  if (a.model == nullptr || b.model == nullptr) return false;
  return CentreInside(*a.model, a.cam_T_model, b) || CentreInside(*b.model, b.cam_T_model, a);
}

int CentreInsideAny(const Model& model, const RigidTransform& cam_T_model, const PosedModel* others,
                    size_t n) {
  for (size_t i = 0; i < n; ++i) {
    if (CentreInside(model, cam_T_model, others[i])) return static_cast<int>(i);
  }
  return -1;
}

}  // namespace sh
