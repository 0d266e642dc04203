#include "firmware/web/overlay_edges.hpp"

#include <memory>

#include "recog/pipeline/outline_projection.hpp"

namespace sh::fw::web {

std::vector<std::vector<float>> VolumeLines(const StereoCalibration& calibration,
                                            const RigidTransform& left_T_box, const float min_mm[3],
                                            const float max_mm[3], int side) {
  const auto corner = [&](int bits) {
    return Eigen::Vector3f((bits & 1) ? max_mm[0] : min_mm[0], (bits & 2) ? max_mm[1] : min_mm[1],
                           (bits & 4) ? max_mm[2] : min_mm[2]);
  };
  std::vector<Eigen::Vector3f> ends;
  for (int a = 0; a < 8; ++a) {
    for (int axis = 0; axis < 3; ++axis) {
      if (a & (1 << axis)) continue;  // each edge once: from the corner without the axis bit
      ends.push_back(corner(a));
      ends.push_back(corner(a | (1 << axis)));
    }
  }
  return ProjectSegments(calibration, left_T_box, ends, side);
}

std::vector<std::vector<float>> TableGridLines(const StereoCalibration& calibration,
                                               const RigidTransform& left_T_table, int side) {
  std::vector<Eigen::Vector3f> ends;
  const float h = kTableGridHalfMm;
  for (float v = -h; v <= h + 0.5f; v += kTableGridStepMm) {
    ends.emplace_back(v, -h, 0.0f);
    ends.emplace_back(v, h, 0.0f);
    ends.emplace_back(-h, v, 0.0f);
    ends.emplace_back(h, v, 0.0f);
  }
  return ProjectSegments(calibration, left_T_table, ends, side);
}

std::vector<OverlayObject> ComputeOverlay(const StereoCalibration& calibration,
                                          const LiveSnapshot& snapshot,
                                          const protocol::ResultSet& set) {
  const size_t n = set.object_count < protocol::kMaxResultObjects ? set.object_count
                                                                  : protocol::kMaxResultObjects;
  std::vector<OverlayObject> out(n);
  // The models, posed in the left camera; an object without its model is not drawn.
  std::unique_ptr<Model[]> models = std::make_unique<Model[]>(n);
  std::vector<PosedModel> posed;
  std::vector<size_t> posed_object;
  for (size_t i = 0; i < n; ++i) {
    const protocol::ObjectPose& p = set.objects[i];
    out[i].model_id = p.model_id;
    out[i].score = p.score;
    if (!snapshot.CopyModel(p.model_id, &models[i])) continue;
    out[i].name = models[i].name;
    posed.push_back({&models[i], snapshot.camera_T_out() * protocol::PoseTransform(p)});
    posed_object.push_back(i);
  }
  for (int side = 0; side < 2; ++side) {
    std::vector<std::vector<PixelPolyline>> lines =
        VisibleOutlines(calibration, posed.data(), posed.size(), side);
    for (size_t k = 0; k < posed.size(); ++k)
      out[posed_object[k]].lines[side] = std::move(lines[k]);
  }
  return out;
}

}  // namespace sh::fw::web
