// The random-match model of thesis section 2.3 (eqs. 2.15-2.21) against simulation: random point
// sets in 100 x 100 x 70 mm, sigma 5 mm, one valid scene basis per set (non-collinear, sides at
// most 70 mm), best vote per model with three-point hashing (hash fn 2, points only).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>

#include "tests/support/tables_fixture.hpp"

namespace sh {
namespace {

// Expected best relative vote of a model with M points and t bases among S random points.
double ExpectedRelativeVote(int M, int t, int S, double sigma_mm, double volume_mm3) {
  const double c = 1.0 / (2.0 * std::sqrt(2.0));                                // eq. 2.15
  const double U = 2.0 * M_PI * std::sqrt(2.0 * M_PI) * std::pow(sigma_mm, 3);  // eq. 2.15
  const double r = U / volume_mm3;                                              // eq. 2.16
  const double p = 1.0 - std::pow(1.0 - r, S - 2);                              // eq. 2.17
  const int n = M - 2;
  std::vector<double> q(n + 1), w(n + 2, 0.0), v(n + 2, 0.0);
  for (int k = 0; k <= n; ++k)  // eq. 2.18
    q[k] = std::exp(std::lgamma(n + 1) - std::lgamma(k + 1) - std::lgamma(n - k + 1) +
                    k * std::log(p) + (n - k) * std::log1p(-p));
  for (int k = n; k >= 0; --k) w[k] = w[k + 1] + q[k];                // eq. 2.19
  for (int k = 0; k <= n; ++k) v[k] = 1.0 - std::pow(1.0 - w[k], t);  // eq. 2.20
  double expected_k = 0.0;
  for (int k = 0; k <= n; ++k) expected_k += k * (k < n ? v[k] - v[k + 1] : v[k]);  // eq. 2.21
  return expected_k * c / n;
}

TEST(RandomMatches, AverageVoteFollowsTheBinomialModel) {
  auto table = testing::BuildTable(HashFunction::kThreePointsCentroid);
  RecognizerConfig config;
  config.sigma_point_mm = 5.0f;
  config.vote_threshold = 0.0f;
  config.order = BasisOrder::kFileOrder;
  auto recognizer = testing::MakeRecognizer(table->view, config);
  const std::vector<Model> models = testing::ModelsOf(table->view);
  const int bases[] = {42, 110, 20, 684, 72, 168};
  std::mt19937 rng(2024);
  std::uniform_real_distribution<float> ux(0, 100), uz(0, 70);
  auto scene = std::make_unique<Scene>();
  Vector<Hypothesis, kMaxHypothesesPerBasis> hypotheses;
  std::printf("S  model      simulated  model(eq.2.21)\n");
  FILE* csv = std::fopen((::testing::TempDir() + "/random_votes.csv").c_str(), "w");
  double worst_ratio = 1.0;
  for (int S = 20; S <= 100; S += 20) {
    double sum[6] = {};
    const int trials = 100;
    for (int trial = 0; trial < trials; ++trial) {
      scene->clear();
      for (int i = 0; i < S; ++i) {
        ScenePoint p;
        p.p_mm = {ux(rng), ux(rng), uz(rng)};
        ASSERT_TRUE(scene->points.push_back(p));
      }
      recognizer->PrepareScene(*scene);
      // The first valid basis in random order (sides at most 70 mm, non-collinear).
      SceneBasis basis;
      for (;;) {
        std::uniform_int_distribution<int> ui(0, S - 1);
        const int a = ui(rng), b = ui(rng), c = ui(rng);
        if (a == b || b == c || a == c) continue;
        const Eigen::Vector3f &pa = scene->points[a].p_mm, &pb = scene->points[b].p_mm,
                              &pc = scene->points[c].p_mm;
        BasisLimits limits = table->view.limits();
        limits.max_point_spacing_mm = 70.0f;
        RigidTransform f;
        if (!ThreePointFrame(HashFunction::kThreePointsCentroid, pa, pb, pc, limits, &f)) continue;
        basis.f[0] = uint16_t(a), basis.f[1] = uint16_t(b), basis.f[2] = uint16_t(c);
        break;
      }
      float best[kMaxTableModels];
      recognizer->VoteForBasis(basis, hypotheses, best);
      for (int m = 0; m < 6; ++m) sum[m] += best[m];
    }
    for (int m = 0; m < 6; ++m) {
      const double simulated = sum[m] / trials;
      const double expected =
          ExpectedRelativeVote(models[m].n_corners, bases[m], S, 5.0, 100.0 * 100.0 * 70.0);
      std::printf("%3d %-10s %8.4f  %8.4f\n", S, models[m].name, simulated, expected);
      if (csv) std::fprintf(csv, "%d,%s,%.5f,%.5f\n", S, models[m].name, simulated, expected);
      worst_ratio = std::max(worst_ratio, std::max(simulated / expected, expected / simulated));
      // The model predicts the mean within 40 % (measured worst: 24 %); the thesis's figure 2.8
      // shows the same: the uniform-hash-value assumption is rough for few points; the trend must
      // hold.
      EXPECT_LT(simulated, expected * 1.4 + 0.01) << models[m].name << " S=" << S;
      EXPECT_GT(simulated, expected / 1.4 - 0.01) << models[m].name << " S=" << S;
    }
  }
  if (csv) std::fclose(csv);
  std::printf("worst simulated/model ratio: %.2f\n", worst_ratio);
}

}  // namespace
}  // namespace sh
