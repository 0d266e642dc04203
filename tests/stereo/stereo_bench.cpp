// Sloppy stereo timing: 300 x 300 corners and 150 x 150 lines on a synthetic distorted rig,
// features spread through a thesis-sized working volume (400 x 400 x 70 mm, 700 mm away).
#include <benchmark/benchmark.h>

#include <memory>
#include <random>
#include <vector>

#include "recog/stereo/sloppy_stereo.hpp"
#include "tests/support/stereo_scene.hpp"

namespace sh {
namespace {

const Eigen::Vector3d kBoxMin(-140, -200, 665), kBoxMax(260, 200, 735);

Eigen::Vector3d RandomInBox(std::mt19937& rng) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const Eigen::Vector3d t(u(rng), u(rng), u(rng));
  return kBoxMin + t.cwiseProduct(kBoxMax - kBoxMin);
}

struct Fixture {
  StereoCalibration calib;
  std::unique_ptr<SloppyStereo> stereo = std::make_unique<SloppyStereo>();
  std::unique_ptr<Scene> scene = std::make_unique<Scene>();
  std::vector<StereoPoint2D> left_points, right_points;
  std::vector<StereoLine2D> left_lines, right_lines;

  Fixture() {
    std::mt19937 rng(99);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    calib = testing::RandomRig(rng, 1.0);
    SloppyStereoConfig config;
    config.volume = WorkingVolume::InLeftCamera(kBoxMin.cast<float>(), kBoxMax.cast<float>());
    if (!stereo->Configure(calib, config).ok()) std::abort();
    while (left_points.size() < 300) {
      Eigen::Vector2d l, r;
      if (!testing::ProjectBoth(calib, RandomInBox(rng), &l, &r)) continue;
      left_points.push_back({static_cast<float>(l.x()), static_cast<float>(l.y()), 1.0f});
      right_points.push_back({static_cast<float>(r.x()), static_cast<float>(r.y()), 1.0f});
    }
    while (left_lines.size() < 150) {
      const Eigen::Vector3d a = RandomInBox(rng);
      const Eigen::Vector3d b =
          a + 60.0 * Eigen::Vector3d(u(rng), u(rng), 0.2 * u(rng)).normalized();
      Eigen::Vector2d la, ra, lb, rb;
      if (!testing::ProjectBoth(calib, a, &la, &ra) || !testing::ProjectBoth(calib, b, &lb, &rb))
        continue;
      left_lines.push_back(testing::ChordLine(la, lb));
      right_lines.push_back(testing::ChordLine(ra, rb));
    }
  }
};

Fixture& GetFixture() {
  static Fixture f;
  return f;
}

void BM_SloppyPoints300x300(benchmark::State& state) {
  Fixture& f = GetFixture();
  PointStereoStats stats;
  for (auto _ : state) {
    const Status s =
        f.stereo->MatchPoints(f.left_points.data(), f.left_points.size(), f.right_points.data(),
                              f.right_points.size(), f.scene->points, &stats);
    benchmark::DoNotOptimize(s.ok());
  }
  state.counters["within_Ts"] = static_cast<double>(stats.within_tolerance);
  state.counters["points"] = static_cast<double>(stats.accepted);
  state.counters["truncated"] = stats.truncated ? 1.0 : 0.0;
}
BENCHMARK(BM_SloppyPoints300x300)->Unit(benchmark::kMillisecond);

void BM_SloppyLines150x150(benchmark::State& state) {
  Fixture& f = GetFixture();
  LineStereoStats stats;
  for (auto _ : state) {
    const Status s =
        f.stereo->MatchLines(f.left_lines.data(), f.left_lines.size(), f.right_lines.data(),
                             f.right_lines.size(), f.scene->lines, &stats);
    benchmark::DoNotOptimize(s.ok());
  }
  state.counters["pairs"] = static_cast<double>(stats.pairs);
  state.counters["lines"] = static_cast<double>(stats.accepted);
  state.counters["truncated"] = stats.truncated ? 1.0 : 0.0;
}
BENCHMARK(BM_SloppyLines150x150)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace sh

BENCHMARK_MAIN();
