#include "firmware/web/overlay_edges.hpp"

#include <memory>

#include "recog/verify/view_camera.hpp"
#include "recog/verify/visible_edges.hpp"

namespace sh::fw::web {
namespace {

constexpr float kSampleStepPx = 2.0f;
constexpr float kMinDepthMm = 1.0f;
constexpr int kMaxPointsPerRun = 24;  // a polyline follows the lens's bending with this many

// The visible runs of `visible` as polylines of distorted pixels.
void AppendRuns(const ViewCamera& view, const VisibleEdgeSet& visible,
                std::vector<std::vector<float>>* lines) {
  const double max_r2 = MaxImageRadius2(view.intrinsics);
  for (int e = 0; e < visible.n_edges; ++e) {
    const VisibleEdge& edge = visible.edges[e];
    for (int r = 0; r < edge.n_runs; ++r) {
      const VisibleRun& run = edge.runs[r];
      const int samples = run.end - run.first;
      if (samples < 2) continue;
      const int step = (samples + kMaxPointsPerRun - 1) / kMaxPointsPerRun;
      std::vector<float> line;
      for (int i = run.first;; i += step) {
        if (i > run.end - 1) i = run.end - 1;
        Eigen::Vector2f px;
        const Eigen::Vector3f x =
            PointAtImageFraction(edge, SampleImageFraction(i, edge.n_samples));
        if (ProjectInView(view.intrinsics, max_r2, x, &px)) {
          line.push_back(px.x());
          line.push_back(px.y());
        }
        if (i == run.end - 1) break;
      }
      if (line.size() >= 4) lines->push_back(std::move(line));
    }
  }
}

constexpr int kSegmentSteps = 32;  // points along each straight segment (the lens bends them)

// Straight segments ends[2k]..ends[2k+1] (in the frame left_T_frame maps into the left camera)
// projected into image `side`: polylines in full-size pixels, cut where they leave the image or
// pass behind the camera.
std::vector<std::vector<float>> ProjectSegments(const StereoCalibration& calibration,
                                                const RigidTransform& left_T_frame,
                                                const std::vector<Eigen::Vector3f>& ends,
                                                int side) {
  const ViewCamera view = side == 0 ? LeftView(calibration) : RightView(calibration);
  const double max_r2 = MaxImageRadius2(view.intrinsics);
  const RigidTransform cam_T_frame = view.cam_T_left * left_T_frame;
  std::vector<std::vector<float>> lines;
  for (size_t s = 0; s + 1 < ends.size(); s += 2) {
    std::vector<float> line;
    for (int i = 0; i <= kSegmentSteps; ++i) {
      const float t = float(i) / kSegmentSteps;
      const Eigen::Vector3f x = cam_T_frame * ((1 - t) * ends[s] + t * ends[s + 1]);
      Eigen::Vector2f px;
      if (x.z() > 0 && ProjectInView(view.intrinsics, max_r2, x, &px)) {
        line.push_back(px.x());
        line.push_back(px.y());
      } else {
        if (line.size() >= 4) lines.push_back(line);
        line.clear();
      }
    }
    if (line.size() >= 4) lines.push_back(std::move(line));
  }
  return lines;
}

}  // namespace

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
  const ViewCamera views[2] = {LeftView(calibration), RightView(calibration)};
  std::unique_ptr<VisibleEdgeSet> visible = std::make_unique<VisibleEdgeSet>();
  std::vector<PosedModel> occluders;
  for (size_t k = 0; k < posed.size(); ++k) {
    occluders.clear();
    for (size_t j = 0; j < posed.size() && occluders.size() < kMaxOccluders; ++j) {
      if (j != k) occluders.push_back(posed[j]);
    }
    for (int side = 0; side < 2; ++side) {
      const Status s =
          ComputeVisibleEdges(views[side], posed[k], occluders.data(), occluders.size(),
                              kSampleStepPx, kMinDepthMm, visible.get());
      if (s.ok()) AppendRuns(views[side], *visible, &out[posed_object[k]].lines[side]);
    }
  }
  return out;
}

}  // namespace sh::fw::web
