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

// Renders the region id (object, face) seen through each pixel centre, then marks pixels whose
// right or lower neighbour shows another region, with the gradient orientation of the region's
// indicator function (Gaussian derivative), as Canny would on an image with distinct face
// intensities.
EdgeMapBuffer RenderEdgeMap(const ViewCamera& view, const std::vector<PosedModel>& objects);

// True if nothing in `objects` lies on the segment from the camera centre to x_cam (a point in
// the camera's frame) more than tolerance_mm before x_cam. Tests every face of every object
// with a winding-angle point-in-polygon test.
bool BruteForceVisible(const ViewCamera& view, const std::vector<PosedModel>& objects,
                       const Eigen::Vector3d& x_cam, double tolerance_mm);

}  // namespace sh::testing
