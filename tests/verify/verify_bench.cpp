// Speed of verification at the thesis' image size (756 x 581) for 50 mm-class objects at about
// half a metre, with edge maps rendered from the true scene.
#include <benchmark/benchmark.h>

#include <vector>

#include "recog/verify/verify.hpp"
#include "tests/support/edge_scene.hpp"
#include "tests/support/test_models.hpp"

namespace sh {
namespace {

using testing::AxisAngleDeg;

struct Scene {
  StereoCalibration calib = testing::TestCalibration();
  Model cube = testing::CubeModel();
  Model star = testing::StarModel();
  std::vector<PosedModel> objects;
  testing::EdgeMapBuffer left{0, 0}, right{0, 0};
  Scene() {
    objects.push_back(
        {&star, {AxisAngleDeg({1, 0, 0}, 125) * AxisAngleDeg({0, 0, 1}, 10), {30, 10, 460}}});
    objects.push_back(
        {&cube, {AxisAngleDeg({1, 0.3f, 0}, 35) * AxisAngleDeg({0, 1, 0}, 40), {-70, -30, 500}}});
    for (int k = 0; k < 4; ++k) {  // further accepted objects, around but not over the others
      objects.push_back(
          {&cube, {AxisAngleDeg({0, 1, 0}, 20.0f * k), {-120.0f + 80.0f * k, 110, 520}}});
    }
    left = testing::RenderEdgeMap(LeftView(calib), objects);
    right = testing::RenderEdgeMap(RightView(calib), objects);
  }
};

const Scene& GetScene() {
  static const Scene scene;
  return scene;
}

void RunVerify(benchmark::State& state, int object, int n_occluders) {
  const Scene& s = GetScene();
  const PosedModel* occluders = s.objects.data() + 2;
  const VerifyConfig config;
  VerifyResult last;
  for (auto _ : state) {
    Result<VerifyResult> r = VerifyHypothesis(s.calib, s.left.const_view(), s.right.const_view(),
                                              s.objects[object], occluders, n_occluders, config);
    benchmark::DoNotOptimize(r);
    last = *r;
  }
  state.counters["accepted"] = last.accepted;
  state.counters["samples"] = last.samples_left + last.samples_right;
  state.counters["score_l"] = last.score_left;
  state.counters["score_r"] = last.score_right;
}

void BM_VerifyStar(benchmark::State& state) { RunVerify(state, 0, 0); }
void BM_VerifyCube(benchmark::State& state) { RunVerify(state, 1, 0); }
void BM_VerifyStarFourOccluders(benchmark::State& state) { RunVerify(state, 0, 4); }

void BM_VisibleEdgesStarLeft(benchmark::State& state) {
  const Scene& s = GetScene();
  const ViewCamera view = LeftView(s.calib);
  VisibleEdgeSet set;
  for (auto _ : state) {
    Status st = ComputeVisibleEdges(view, s.objects[0], nullptr, 0, 1.0f, 1.0f, &set);
    benchmark::DoNotOptimize(st);
    benchmark::DoNotOptimize(set);
  }
  state.counters["visible"] = set.n_visible_samples;
}

BENCHMARK(BM_VerifyStar)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_VerifyCube)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_VerifyStarFourOccluders)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_VisibleEdgesStarLeft)->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace sh

BENCHMARK_MAIN();
