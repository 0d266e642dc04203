// Synthetic edge scenes for the verification tests and benchmark: edge maps rendered by casting a
// ray through every pixel (independent of the hidden-line code under test), and a brute-force
// visibility oracle.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "recog/image/edge_map.hpp"
#include "recog/verify/view_camera.hpp"
#include "tests/support/calibrations.hpp"
#include "tests/support/test_models.hpp"

namespace sh::testing {

// Rotation about a unit axis by an angle in degrees.
Eigen::Matrix3f AxisAngleDeg(const Eigen::Vector3f& axis, float angle_deg);

struct EdgeMapBuffer {
  int width = 0, height = 0;
  std::vector<uint8_t> edge, orientation;
  EdgeMapBuffer(int w, int h) : width(w), height(h), edge(w * h, 0), orientation(w * h, 0) {}
  EdgeMapView view() {
    return {{edge.data(), width, height, width}, {orientation.data(), width, height, width}};
  }
  ConstEdgeMapView const_view() const {
    return {{edge.data(), width, height, width}, {orientation.data(), width, height, width}};
  }
};

// A cube and a star posed apart, both wholly in view of both cameras of TestCalibration: the
// scene of the verification and edge-fit tests. Not copyable: the poses point at the models.
struct CubeAndStarScene {
  CubeAndStarScene() = default;
  CubeAndStarScene(const CubeAndStarScene&) = delete;
  CubeAndStarScene& operator=(const CubeAndStarScene&) = delete;

  StereoCalibration calib = TestCalibration();
  Model cube = CubeModel();
  Model star = StarModel();
  PosedModel cube_pose{
      &cube, {AxisAngleDeg({1, 0.3f, 0}, 35) * AxisAngleDeg({0, 1, 0}, 40), {10, -5, 480}}};
  PosedModel star_pose{&star,
                       {AxisAngleDeg({1, 0, 0}, 125) * AxisAngleDeg({0, 0, 1}, 10), {30, 10, 460}}};
};

// Renders the region id (object, face) seen through each pixel centre, then marks pixels whose
// right or lower neighbour shows another region, with the gradient orientation of the region's
// indicator function (Gaussian derivative), as Canny would on an image with distinct face
// intensities.
EdgeMapBuffer RenderEdgeMap(const ViewCamera& view, const std::vector<PosedModel>& objects);

// The region seen through each pixel centre (row-major, width x height of the camera): 0 for
// the background, 64 k + f + 1 for face f of objects[k].
std::vector<int> RenderRegions(const ViewCamera& view, const std::vector<PosedModel>& objects);

// True if nothing in `objects` lies on the segment from the camera centre to x_cam (a point in
// the camera's frame) more than tolerance_mm before x_cam. Tests every face of every object
// with a winding-angle point-in-polygon test. Faces whose planes pass within min_sin_incidence
// (sine of the angle between the ray and the plane) of the ray are skipped: seen edge-on, a face
// covers no pixel, and where the ray meets its plane is up to rounding.
bool BruteForceVisible(const ViewCamera& view, const std::vector<PosedModel>& objects,
                       const Eigen::Vector3d& x_cam, double tolerance_mm,
                       double min_sin_incidence = 0.0);

}  // namespace sh::testing
