// The overlay of the live view: each object of a result set as the visible edges of its model
// (hidden lines removed, the other objects as occluders), projected into the left and right
// images as polylines in full-size pixels, with its name and score. Computed on the server thread
// for the page, from the snapshot's models and poses.
#pragma once

#include <string>
#include <vector>

#include "firmware/result_codec.hpp"
#include "firmware/web/live_snapshot.hpp"
#include "recog/camera/camera_model.hpp"
#include "recog/geometry/rigid_transform.hpp"

namespace sh::fw::web {

// NOLINTNEXTLINE(bugprone-reserved-identifier): clang-tidy 14 names the implicit array copy's index
struct OverlayObject {
  int model_id = 0;
  std::string name;
  double score = 0;
  // Per side (0 left, 1 right): polylines of x, y pairs in the full-size image.
  std::vector<std::vector<float>> lines[2];
};

// The overlay of `set` (poses in the output frame; snapshot.camera_T_out() maps them back).
// Objects whose model the snapshot does not hold, or whose pose cannot be projected, are left
// without lines but keep their name.
std::vector<OverlayObject> ComputeOverlay(const StereoCalibration& calibration,
                                          const LiveSnapshot& snapshot,
                                          const protocol::ResultSet& set);

// The working volume box (volume_min_mm .. volume_max_mm in the frame left_T_box maps into the
// left camera) as its 12 edges projected into image `side` (0 left, 1 right): polylines in
// full-size pixels, cut where an edge leaves the image or passes behind the camera.
std::vector<std::vector<float>> VolumeLines(const StereoCalibration& calibration,
                                            const RigidTransform& left_T_box, const float min_mm[3],
                                            const float max_mm[3], int side);

// A square grid on the table plane (z = 0 of left_T_table), kTableGridHalfMm around its origin
// with a line every kTableGridStepMm, projected into image `side` as VolumeLines projects.
inline constexpr float kTableGridHalfMm = 300.0f;
inline constexpr float kTableGridStepMm = 50.0f;
std::vector<std::vector<float>> TableGridLines(const StereoCalibration& calibration,
                                               const RigidTransform& left_T_table, int side);

}  // namespace sh::fw::web
