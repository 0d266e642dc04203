#include "firmware/output_frame.hpp"

#include <Eigen/Geometry>

namespace sh::fw {

void TransformResultSet(const RigidTransform& out_T_camera, protocol::ResultSet* set) {
  const Eigen::Matrix3d R = out_T_camera.R.cast<double>();
  const Eigen::Quaterniond q_out_cam = Eigen::Quaterniond(R).normalized();
  const Eigen::Vector3d t = out_T_camera.t_mm.cast<double>();
  for (size_t i = 0; i < set->object_count; ++i) {
    protocol::ObjectPose& p = set->objects[i];
    const Eigen::Vector3d t_cam(p.cam_t_model_mm[0], p.cam_t_model_mm[1], p.cam_t_model_mm[2]);
    const Eigen::Quaterniond q_cam(p.cam_q_model[0], p.cam_q_model[1], p.cam_q_model[2],
                                   p.cam_q_model[3]);
    const Eigen::Vector3d t_out = R * t_cam + t;
    const Eigen::Quaterniond q_out = (q_out_cam * q_cam).normalized();
    for (int k = 0; k < 3; ++k) p.cam_t_model_mm[k] = t_out[k];
    p.cam_q_model[0] = q_out.w();
    p.cam_q_model[1] = q_out.x();
    p.cam_q_model[2] = q_out.y();
    p.cam_q_model[3] = q_out.z();
  }
}

}  // namespace sh::fw
