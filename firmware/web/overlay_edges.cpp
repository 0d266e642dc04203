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

}  // namespace

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
