// Speed of the per-image feature extraction on synthetic scenes of camera size (756x581) and of
// a large frame (1280x1024), and of binning a 5 MP image (2592x2048) to a frame. Run:
// build/<dir>/tests/image/image_bench
#include <benchmark/benchmark.h>

#include <memory>
#include <vector>

#include "recog/image/binning.hpp"
#include "recog/image/features.hpp"
#include "tests/support/synthetic_image.hpp"

namespace sh {
namespace {

struct Frame {
  std::vector<uint8_t> pixels;
  ConstGrayView view;
};

const Frame& SceneFrame(int w, int h) {
  static Frame frames[2];
  Frame& f = frames[w == 756 ? 0 : 1];
  if (f.pixels.empty()) {
    testing::SyntheticImage synth(w, h, 35.0);
    for (const testing::Polygon& p : testing::TestScene(w, h, 190.0)) synth.Fill(p, 4);
    synth.Blur(0.8);
    synth.AddNoise(2.0, 1);
    f.view = synth.ToGray(f.pixels);
  }
  return f;
}

FeatureWorkspace& Workspace() {
  static auto ws = MakeWorkspace<FeatureWorkspace>();
  return *ws;
}

void BM_Corners(benchmark::State& state) {
  const Frame& f = SceneFrame(int(state.range(0)), int(state.range(1)));
  CornerConfig config;
  config.sigma_px = float(state.range(2));
  config.nms_radius_px = std::max(3, int(state.range(2)));
  static Vector<Corner2D, kMaxCorners2d> corners;
  for (auto _ : state) {
    if (!DetectCorners(f.view, config, Workspace().filter, corners).ok())
      state.SkipWithError("fail");
    benchmark::DoNotOptimize(corners.data());
  }
  state.counters["corners"] = double(corners.size());
}

void BM_Canny(benchmark::State& state) {
  const Frame& f = SceneFrame(int(state.range(0)), int(state.range(1)));
  CannyConfig config;
  config.sigma_px = float(state.range(2));
  EdgeMapView edges;
  CannyStats stats;
  for (auto _ : state) {
    if (!DetectEdges(f.view, config, Workspace().filter, Workspace().edges, edges, &stats).ok()) {
      state.SkipWithError("fail");
    }
    benchmark::ClobberMemory();
  }
  state.counters["edge_px"] = double(stats.edge_pixels);
}

void BM_Hough(benchmark::State& state) {
  const Frame& f = SceneFrame(int(state.range(0)), int(state.range(1)));
  EdgeMapView edges;
  if (!DetectEdges(f.view, CannyConfig{}, Workspace().filter, Workspace().edges, edges).ok()) {
    state.SkipWithError("canny failed");
    return;
  }
  const ConstEdgeMapView cedges{edges.edge, edges.orientation};
  static Vector<Line2D, kMaxLines2d> lines;
  HoughStats stats;
  for (auto _ : state) {
    if (!DetectLines(cedges, HoughConfig{}, Workspace().hough, lines, &stats).ok()) {
      state.SkipWithError("fail");
    }
    benchmark::DoNotOptimize(lines.data());
  }
  state.counters["lines"] = double(lines.size());
  state.counters["edge_px"] = double(stats.edge_pixels);
}

void BM_ExtractFeatures(benchmark::State& state) {
  const Frame& f = SceneFrame(int(state.range(0)), int(state.range(1)));
  const FeatureConfig config =
      state.range(2) == 0 ? FeatureConfig::DarkBackground() : FeatureConfig::LightBackground();
  static auto features = std::make_unique<ImageFeatures>();
  for (auto _ : state) {
    if (!ExtractFeatures(f.view, config, Workspace(), *features).ok()) state.SkipWithError("fail");
    benchmark::DoNotOptimize(features.get());
  }
  state.counters["corners"] = double(features->corners.size());
  state.counters["lines"] = double(features->lines.size());
}

// Binning a 5 MP sensor's image 2 x 2 into a frame (what DirectoryCamera and `recognize` add
// per image for such a camera; a binning sensor or ISP does it in hardware).
void BM_BinGray(benchmark::State& state) {
  const int w = int(state.range(0)), h = int(state.range(1)), f = int(state.range(2));
  std::vector<uint8_t> full(size_t(w) * h), binned(size_t(w / f) * (h / f));
  for (size_t i = 0; i < full.size(); ++i) full[i] = uint8_t(i * 2654435761u >> 24);
  for (auto _ : state) {
    if (!BinGray({full.data(), w, h, w}, f, {binned.data(), w / f, h / f, w / f}).ok()) {
      state.SkipWithError("fail");
    }
    benchmark::DoNotOptimize(binned.data());
  }
}

BENCHMARK(BM_Corners)
    ->ArgNames({"w", "h", "sigma_c"})
    ->Args({756, 581, 2})
    ->Args({756, 581, 6})
    ->Args({1280, 1024, 2})
    ->Args({1280, 1024, 6})
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Canny)
    ->ArgNames({"w", "h", "sigma"})
    ->Args({756, 581, 1})
    ->Args({756, 581, 2})
    ->Args({1280, 1024, 1})
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Hough)
    ->ArgNames({"w", "h"})
    ->Args({756, 581})
    ->Args({1280, 1024})
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_ExtractFeatures)
    ->ArgNames({"w", "h", "light"})
    ->Args({756, 581, 0})
    ->Args({756, 581, 1})
    ->Args({1280, 1024, 0})
    ->Args({1280, 1024, 1})
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_BinGray)
    ->ArgNames({"w", "h", "factor"})
    ->Args({2592, 2048, 2})
    ->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace sh

BENCHMARK_MAIN();
