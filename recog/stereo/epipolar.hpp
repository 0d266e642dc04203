// Epipolar geometry between the left and right camera, with lens distortion kept in the model.
//
// Images are never rectified. Distances to an epipolar "curve" (the distorted image of an
// epipolar line) are measured after undistortion: the right pixel is mapped to normalised
// coordinates (x/z, y/z), its distance to the straight epipolar line in the right normalised
// plane is taken there and converted to pixels by multiplying with the right camera's fx. This
// equals the pixel distance in an undistorted image with focal length fx; in the distorted image
// it differs by the local magnification of the distortion (a few per cent towards the corners
// for typical lenses), which is well inside the tolerance T_s it is compared with.
#pragma once

#include <Eigen/Core>

#include "recog/camera/camera_model.hpp"

namespace sh {

// Essential matrix E = [T]x R: x_r^T E x_l = 0 for homogeneous normalised coordinates
// x_l = (x/z, y/z, 1) in the left and x_r in the right camera.
Eigen::Matrix3d EssentialMatrix(const StereoCalibration& calib);

// The epipolar line (a, b, c), a x + b y + c = 0 with a^2 + b^2 = 1, in the right normalised
// plane of the left normalised point xy_left. Zero when undefined (xy_left at the epipole).
Eigen::Vector3d RightEpipolarLine(const Eigen::Matrix3d& essential, const Eigen::Vector2d& xy_left);

// Distance in right-image pixels (see above) of right_px to the epipolar curve of left_px.
// Infinite when the epipolar line is undefined.
double EpipolarDistancePx(const StereoCalibration& calib, const Eigen::Vector2d& left_px,
                          const Eigen::Vector2d& right_px);

// Angle in degrees between the two interpretation planes of the 3-D segment a-b (left camera
// frame, mm): the plane through the left camera centre and the segment, and the plane through
// the right camera centre and it. Near 0 for a segment running close to the epipolar direction
// (parallel to the baseline), whose two image lines do not fix its depth; line stereo rejects
// pairs whose planes meet at less than SloppyStereoConfig::min_plane_angle_deg. 0 for a
// degenerate segment (a == b, or a plane through both camera centres).
double InterpretationPlaneAngleDeg(const StereoCalibration& calib, const Eigen::Vector3d& a_mm,
                                   const Eigen::Vector3d& b_mm);

}  // namespace sh
