// Poses from the left camera into the frame the PLC asked for (config output_frame): the table
// (conveyor) or the robot (base for fixed cameras, flange for cameras on the robot), through a
// constant transform out_T_camera from the table pose or the hand-eye calibration.
#pragma once

#include "firmware/result_codec.hpp"
#include "recog/geometry/rigid_transform.hpp"

namespace sh::fw {

// out_T_model = out_T_camera * camera_T_model for every object of the set, in double
// precision; the quaternion is renormalised. The set's output_frame is left to the caller.
void TransformResultSet(const RigidTransform& out_T_camera, protocol::ResultSet* set);

}  // namespace sh::fw
