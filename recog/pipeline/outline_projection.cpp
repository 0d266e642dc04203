#include "recog/pipeline/outline_projection.hpp"

#include <memory>

#include "recog/verify/visible_edges.hpp"

namespace sh {
namespace {

constexpr float kSampleStepPx = 2.0f;
constexpr float kMinDepthMm = 1.0f;
constexpr int kMaxPointsPerRun = 24;  // a polyline follows the lens's bending with this many
constexpr int kSegmentSteps = 32;     // points along each straight segment (the lens bends them)

// The visible runs of `visible` as polylines of distorted pixels.
void AppendRuns(const ViewCamera& view, const VisibleEdgeSet& visible,
                std::vector<PixelPolyline>* lines) {
  const double max_r2 = MaxImageRadius2(view.intrinsics);
  for (int e = 0; e < visible.n_edges; ++e) {
    const VisibleEdge& edge = visible.edges[e];
    for (int r = 0; r < edge.n_runs; ++r) {
      const VisibleRun& run = edge.runs[r];
      const int samples = run.end - run.first;
      if (samples < 2) continue;
      const int step = (samples + kMaxPointsPerRun - 1) / kMaxPointsPerRun;
      PixelPolyline line;
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

std::vector<std::vector<PixelPolyline>> VisibleOutlines(const StereoCalibration& calibration,
                                                        const PosedModel* posed, size_t n,
                                                        int side) {
  std::vector<std::vector<PixelPolyline>> lines(n);
  const ViewCamera view = side == 0 ? LeftView(calibration) : RightView(calibration);
  std::unique_ptr<VisibleEdgeSet> visible = std::make_unique<VisibleEdgeSet>();
  std::vector<PosedModel> occluders;
  for (size_t k = 0; k < n; ++k) {
    occluders.clear();
    for (size_t j = 0; j < n && occluders.size() < kMaxOccluders; ++j) {
      if (j != k) occluders.push_back(posed[j]);
    }
    const Status s = ComputeVisibleEdges(view, posed[k], occluders.data(), occluders.size(),
                                         kSampleStepPx, kMinDepthMm, visible.get());
    if (s.ok()) AppendRuns(view, *visible, &lines[k]);
  }
  return lines;
}

std::vector<PixelPolyline> ProjectSegments(const StereoCalibration& calibration,
                                           const RigidTransform& left_T_frame,
                                           const std::vector<Eigen::Vector3f>& ends, int side) {
  const ViewCamera view = side == 0 ? LeftView(calibration) : RightView(calibration);
  const double max_r2 = MaxImageRadius2(view.intrinsics);
  const RigidTransform cam_T_frame = view.cam_T_left * left_T_frame;
  std::vector<PixelPolyline> lines;
  for (size_t s = 0; s + 1 < ends.size(); s += 2) {
    PixelPolyline line;
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

}  // namespace sh
