// A rigid transform stored in an OpenCV YAML file as two matrices: a 3x3 rotation (row-major)
// and a 3x1 or 1x3 translation in millimetres. Shared by the table pose (table_yaml.hpp) and the
// hand-eye calibration (handeye_yaml.hpp).
#pragma once

#include <Eigen/Core>
#include <cstddef>

#include "recog/base/status.hpp"
#include "recog/camera/opencv_yaml.hpp"
#include "recog/geometry/rigid_transform.hpp"

namespace sh {

// The two matrices as read (both must be present): shapes checked, values converted. Messages
// name the keys.
Status PoseFromYaml(const YamlMatrix& R, const YamlMatrix& t, const char* r_name,
                    const char* t_name, Eigen::Matrix3d* R_out, Eigen::Vector3d* t_out);

// R a rotation (ValidateRotation), t finite and at most max_distance_mm from the origin; `what`
// says what the pose is in the message ("a table pose", "a hand-eye pose").
Status CheckPose(const Eigen::Matrix3d& R, const Eigen::Vector3d& t_mm, const char* r_name,
                 const char* t_name, double max_distance_mm, const char* what);

// The transform with R replaced by its nearest exact rotation.
RigidTransform PoseTransform(const Eigen::Matrix3d& R, const Eigen::Vector3d& t_mm);

// Appends both matrices; false when they do not fit.
bool YamlAppendPose(char* out, size_t capacity, size_t* used, const char* r_name,
                    const char* t_name, const RigidTransform& pose);

}  // namespace sh
