// Hidden-line computation checked against an independent brute-force ray caster.
#include "recog/verify/visible_edges.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "tests/support/edge_scene.hpp"
#include "tests/support/test_models.hpp"

namespace sh {
namespace {

using testing::AxisAngleDeg;
using testing::BruteForceVisible;

struct Agreement {
  int samples = 0;
  int mismatches = 0;
  int edges_with_visible_samples = 0;
  int partially_hidden_edges = 0;  // some samples visible, some hidden
};

const VisibleEdge* FindEdge(const VisibleEdgeSet& set, int e) {
  for (int k = 0; k < set.n_edges; ++k) {
    if (set.edges[k].edge == e) return &set.edges[k];
  }
  return nullptr;
}

// Compares every sample of every edge of `object` with the brute-force oracle over `scene`
// (which contains the object and its occluders). Edges absent from the set are sampled
// independently and must be hidden throughout.
Agreement Compare(const ViewCamera& view, const PosedModel& object,
                  const std::vector<PosedModel>& scene, const VisibleEdgeSet& set) {
  Agreement a;
  const Model& m = *object.model;
  const RigidTransform cam_T_model = view.cam_T_left * object.cam_T_model;
  for (int e = 0; e < m.n_edges; ++e) {
    const VisibleEdge* ve = FindEdge(set, e);
    if (ve == nullptr) {
      const Eigen::Vector3f pa = cam_T_model * m.corner(m.edges[e].a);
      const Eigen::Vector3f pb = cam_T_model * m.corner(m.edges[e].b);
      constexpr int kSamples = 64;
      for (int i = 0; i < kSamples; ++i) {
        const float t = (i + 0.5f) / kSamples;
        ++a.samples;
        if (BruteForceVisible(view, scene, (pa + t * (pb - pa)).cast<double>(),
                              kOcclusionToleranceMm)) {
          ++a.mismatches;
        }
      }
      continue;
    }
    ++a.edges_with_visible_samples;
    bool any_hidden = false;
    for (int i = 0; i < ve->n_samples; ++i) {
      const Eigen::Vector3f x = PointAtImageFraction(*ve, SampleImageFraction(i, ve->n_samples));
      const bool expected = BruteForceVisible(view, scene, x.cast<double>(), kOcclusionToleranceMm);
      const bool got = IsSampleVisible(*ve, i);
      ++a.samples;
      if (expected != got) ++a.mismatches;
      if (!got) any_hidden = true;
    }
    if (any_hidden) ++a.partially_hidden_edges;
  }
  return a;
}

int FrontFaces(const ViewCamera& view, const PosedModel& object) {
  const RigidTransform model_T_cam = (view.cam_T_left * object.cam_T_model).Inverse();
  int n = 0;
  for (int f = 0; f < object.model->n_faces; ++f) {
    const ModelFace& face = object.model->faces[f];
    if (object.model->face_normal(f).dot(model_T_cam.t_mm) > face.offset_mm) ++n;
  }
  return n;
}

class VisibleEdgesTest : public ::testing::Test {
 protected:
  StereoCalibration calib = testing::TestCalibration();
  ViewCamera left = LeftView(calib);
  ViewCamera right = RightView(calib);
  Model cube = testing::CubeModel();
  Model star = testing::StarModel();
};

TEST_F(VisibleEdgesTest, CubeGeneralViewShowsNineOfTwelveEdges) {
  PosedModel object{&cube,
                    {AxisAngleDeg({1, 0.3f, 0}, 35) * AxisAngleDeg({0, 1, 0}, 40), {10, -5, 480}}};
  ASSERT_EQ(FrontFaces(left, object), 3);  // a general view: three faces seen
  VisibleEdgeSet set;
  ASSERT_TRUE(ComputeVisibleEdges(left, object, nullptr, 0, 1.0f, 1.0f, &set).ok());
  EXPECT_EQ(cube.n_edges, 12);
  EXPECT_EQ(set.n_edges, 9);
  for (int k = 0; k < set.n_edges; ++k) {  // convex: visible edges are visible throughout
    ASSERT_EQ(set.edges[k].n_runs, 1);
    EXPECT_EQ(set.edges[k].runs[0].first, 0);
    EXPECT_EQ(set.edges[k].runs[0].end, set.edges[k].n_samples);
  }
  const Agreement a = Compare(left, object, {object}, set);
  EXPECT_EQ(a.mismatches, 0) << "of " << a.samples;
}

TEST_F(VisibleEdgesTest, CubeFaceOnShowsFourEdges) {
  PosedModel object{&cube, {AxisAngleDeg({1, 0, 0}, 180), {0, 0, 500}}};
  // Seen along its axis from the centre line, only the near square is visible.
  VisibleEdgeSet set;
  ASSERT_TRUE(ComputeVisibleEdges(left, object, nullptr, 0, 1.0f, 1.0f, &set).ok());
  EXPECT_EQ(FrontFaces(left, object), 1);
  EXPECT_EQ(set.n_edges, 4);
}

TEST_F(VisibleEdgesTest, StarLowObliqueViewHidesEdgePartsBehindProngs) {
  // The top face is seen at 10 degrees elevation: prongs in front hide whole concave edges and
  // parts of others, which back-face culling alone would draw.
  PosedModel object{&star,
                    {AxisAngleDeg({1, 0, 0}, 100) * AxisAngleDeg({0, 0, 1}, 18), {5, 0, 420}}};
  for (const ViewCamera& view : {left, right}) {
    VisibleEdgeSet set;
    ASSERT_TRUE(ComputeVisibleEdges(view, object, nullptr, 0, 1.0f, 1.0f, &set).ok());
    const Agreement a = Compare(view, object, {object}, set);
    EXPECT_GE(a.partially_hidden_edges, 1);
    EXPECT_GT(set.n_candidate_edges, set.n_edges);  // a front-facing edge hidden throughout
    EXPECT_LT(set.n_visible_samples, set.n_candidate_samples);
    EXPECT_LE(a.mismatches * 500, a.samples) << a.mismatches << " of " << a.samples;
    EXPECT_EQ(set.dropped_runs, 0);
  }
}

TEST_F(VisibleEdgesTest, RandomPosesAgreeWithBruteForce) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> unit(-1.0f, 1.0f);
  std::uniform_real_distribution<float> angle(0.0f, 180.0f);
  int samples = 0, mismatches = 0, partial = 0;
  for (int trial = 0; trial < 40; ++trial) {
    const Model& model = (trial % 2 == 0) ? star : cube;
    const Eigen::Vector3f axis(unit(rng), unit(rng), unit(rng));
    PosedModel object{
        &model,
        {AxisAngleDeg(axis, angle(rng)), {40 * unit(rng), 30 * unit(rng), 450 + 50 * unit(rng)}}};
    VisibleEdgeSet set;
    ASSERT_TRUE(ComputeVisibleEdges(left, object, nullptr, 0, 1.0f, 1.0f, &set).ok());
    const Agreement a = Compare(left, object, {object}, set);
    samples += a.samples;
    mismatches += a.mismatches;
    partial += a.partially_hidden_edges;
  }
  EXPECT_GT(partial, 0);  // the star's self-occlusion was exercised
  EXPECT_LE(mismatches * 1000, samples) << mismatches << " of " << samples;
}

TEST_F(VisibleEdgesTest, AcceptedObjectInFrontHidesEdges) {
  const PosedModel front{&cube, {AxisAngleDeg({0, 1, 0}, 20), {0, 0, 430}}};
  const PosedModel back{&star, {AxisAngleDeg({1, 0, 0}, 150), {25, 10, 540}}};
  VisibleEdgeSet alone, occluded;
  ASSERT_TRUE(ComputeVisibleEdges(left, back, nullptr, 0, 1.0f, 1.0f, &alone).ok());
  ASSERT_TRUE(ComputeVisibleEdges(left, back, &front, 1, 1.0f, 1.0f, &occluded).ok());
  EXPECT_LT(occluded.n_visible_samples, alone.n_visible_samples);
  EXPECT_GT(occluded.n_visible_samples, 0);
  const Agreement a = Compare(left, back, {back, front}, occluded);
  EXPECT_LE(a.mismatches * 500, a.samples) << a.mismatches << " of " << a.samples;
  // The object behind does not hide the one in front.
  VisibleEdgeSet front_alone, front_with_back;
  ASSERT_TRUE(ComputeVisibleEdges(left, front, nullptr, 0, 1.0f, 1.0f, &front_alone).ok());
  ASSERT_TRUE(ComputeVisibleEdges(left, front, &back, 1, 1.0f, 1.0f, &front_with_back).ok());
  EXPECT_EQ(front_with_back.n_visible_samples, front_alone.n_visible_samples);
}

TEST_F(VisibleEdgesTest, RunsAreOrderedAndCountSamples) {
  PosedModel object{&star, {AxisAngleDeg({1, 0, 0}, 105), {0, 0, 400}}};
  VisibleEdgeSet set;
  ASSERT_TRUE(ComputeVisibleEdges(right, object, nullptr, 0, 0.5f, 1.0f, &set).ok());
  int total = 0;
  for (int k = 0; k < set.n_edges; ++k) {
    const VisibleEdge& ve = set.edges[k];
    ASSERT_GE(ve.n_runs, 1);
    for (int r = 0; r < ve.n_runs; ++r) {
      EXPECT_LT(ve.runs[r].first, ve.runs[r].end);
      EXPECT_LE(ve.runs[r].end, ve.n_samples);
      if (r > 0) {
        EXPECT_LT(ve.runs[r - 1].end, ve.runs[r].first);  // hidden gap between runs
      }
      total += ve.runs[r].end - ve.runs[r].first;
    }
  }
  EXPECT_EQ(total, set.n_visible_samples);
}

// A can of 24 facets whose side edges are smooth (ModelEdge::smooth), seen from the side and a
// little above: of the side edges only the two on its silhouette are candidates, each with one
// face turned to the camera and one away; the rims (feature edges) are seen as before.
TEST_F(VisibleEdgesTest, SmoothEdgesOfACanShowOnlyOnItsSilhouette) {
  std::vector<Eigen::Vector2f> outline;
  for (int i = 0; i < 24; ++i) {
    const float a = 2.0f * 3.14159265f * float(i) / 24.0f;
    outline.emplace_back(25.0f * std::cos(a), 25.0f * std::sin(a));
  }
  Model can = testing::MakePrism("can", outline, 40.0f);
  int n_smooth = 0;
  for (int e = 0; e < can.n_edges; ++e) {
    ModelEdge& edge = can.edges[e];
    // Side edges join corner i of the bottom to corner i of the top (MakePrism's numbering).
    if (edge.a % 24 == edge.b % 24) edge.smooth = 1;
    n_smooth += edge.smooth;
  }
  ASSERT_EQ(n_smooth, 24);
  const PosedModel object{&can, {AxisAngleDeg({1, 0, 0}, 70), {0, 0, 500}}};
  const RigidTransform model_T_cam = (left.cam_T_left * object.cam_T_model).Inverse();
  auto front = [&](int f) {
    return can.face_normal(f).dot(model_T_cam.t_mm) > can.faces[f].offset_mm;
  };
  int smooth_between_front_faces = 0;
  for (int e = 0; e < can.n_edges; ++e) {
    smooth_between_front_faces +=
        can.edges[e].smooth && front(can.edges[e].face0) && front(can.edges[e].face1);
  }
  ASSERT_GE(smooth_between_front_faces, 8);  // what a faceted reading would show

  VisibleEdgeSet set;
  ASSERT_TRUE(ComputeVisibleEdges(left, object, nullptr, 0, 1.0f, 1.0f, &set).ok());
  int smooth_seen = 0, rims_seen = 0;
  for (int k = 0; k < set.n_edges; ++k) {
    const ModelEdge& edge = can.edges[set.edges[k].edge];
    if (edge.smooth) {
      ++smooth_seen;
      EXPECT_NE(front(edge.face0), front(edge.face1)) << "edge " << int(set.edges[k].edge);
    } else {
      ++rims_seen;
    }
  }
  EXPECT_EQ(smooth_seen, 2);
  EXPECT_GE(rims_seen, 12);  // the top rim whole, the front of the bottom rim
}

TEST_F(VisibleEdgesTest, SampleSpacingFollowsStep) {
  PosedModel object{&cube, {AxisAngleDeg({1, 1, 0}, 30), {0, 0, 500}}};
  VisibleEdgeSet fine, coarse;
  ASSERT_TRUE(ComputeVisibleEdges(left, object, nullptr, 0, 0.5f, 1.0f, &fine).ok());
  ASSERT_TRUE(ComputeVisibleEdges(left, object, nullptr, 0, 2.0f, 1.0f, &coarse).ok());
  ASSERT_EQ(fine.n_edges, coarse.n_edges);
  for (int k = 0; k < fine.n_edges; ++k) {
    // Consecutive samples are about one step apart in the image.
    const VisibleEdge& ve = coarse.edges[k];
    Eigen::Vector2d p0, p1;
    ASSERT_TRUE(ProjectToPixel(
        calib.left, PointAtImageFraction(ve, SampleImageFraction(0, ve.n_samples)).cast<double>(),
        &p0));
    ASSERT_TRUE(ProjectToPixel(
        calib.left, PointAtImageFraction(ve, SampleImageFraction(1, ve.n_samples)).cast<double>(),
        &p1));
    EXPECT_NEAR((p1 - p0).norm(), 2.0, 0.3);
    EXPECT_NEAR(fine.edges[k].n_samples, 4 * coarse.edges[k].n_samples, 4);
  }
}

TEST_F(VisibleEdgesTest, PoseBehindCameraIsOutOfRange) {
  VisibleEdgeSet set;
  const PosedModel behind{&cube, {Eigen::Matrix3f::Identity(), {0, 0, -500}}};
  const Status s = ComputeVisibleEdges(left, behind, nullptr, 0, 1.0f, 1.0f, &set);
  EXPECT_EQ(s.code(), StatusCode::kOutOfRange);
  EXPECT_NE(std::string(s.message()).find("behind"), std::string::npos);
  const PosedModel straddling{&cube, {Eigen::Matrix3f::Identity(), {0, 0, 10}}};
  EXPECT_EQ(ComputeVisibleEdges(left, straddling, nullptr, 0, 1.0f, 1.0f, &set).code(),
            StatusCode::kOutOfRange);
}

TEST_F(VisibleEdgesTest, BadInputIsReported) {
  VisibleEdgeSet set;
  const PosedModel object{&cube, {Eigen::Matrix3f::Identity(), {0, 0, 500}}};
  EXPECT_EQ(ComputeVisibleEdges(left, {nullptr, {}}, nullptr, 0, 1.0f, 1.0f, &set).code(),
            StatusCode::kInvalidArgument);
  EXPECT_EQ(ComputeVisibleEdges(left, object, nullptr, 0, 0.0f, 1.0f, &set).code(),
            StatusCode::kInvalidArgument);
  EXPECT_EQ(ComputeVisibleEdges(left, object, nullptr, 1, 1.0f, 1.0f, &set).code(),
            StatusCode::kInvalidArgument);
  std::vector<PosedModel> many(kMaxOccluders + 1, object);
  EXPECT_EQ(ComputeVisibleEdges(left, object, many.data(), many.size(), 1.0f, 1.0f, &set).code(),
            StatusCode::kInvalidArgument);
  Model broken = cube;
  broken.edges[3].face1 = 200;
  EXPECT_EQ(
      ComputeVisibleEdges(left, {&broken, object.cam_T_model}, nullptr, 0, 1.0f, 1.0f, &set).code(),
      StatusCode::kInvalidArgument);
  broken = cube;
  broken.n_edges = kMaxModelEdges + 1;
  EXPECT_EQ(CheckModel(broken).code(), StatusCode::kInvalidArgument);
  broken = cube;
  broken.faces[0].normal[2] = 0.0f;
  EXPECT_EQ(CheckModel(broken).code(), StatusCode::kInvalidArgument);
  EXPECT_TRUE(CheckModel(cube).ok());
  EXPECT_TRUE(CheckModel(star).ok());
}

}  // namespace
}  // namespace sh
