#include "recog/hashing/line_direction_index.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <random>
#include <vector>

#include "recog/hashing/recognizer.hpp"
#include "recog/hashing/vote_lut.hpp"
#include "tables/model_files.hpp"
#include "tests/support/random_geometry.hpp"
#include "tests/support/tables_fixture.hpp"
#include "tools/tablegen/table_builder.hpp"

namespace sh {
namespace {

using testing::BuildTable;
using testing::MakeRecognizer;
using testing::ModelsOf;

// The angle cut of the default vote width (recognizer.cpp: 12 kVoteCutoff sigma^2).
constexpr float kAngleCutMm2 = 12.0f * float(kVoteCutoff) * 2.0f * 2.0f;

using testing::RandomUnit;

TEST(LineDirectionIndex, HoldsEveryEntryOnceInBinOrderWithinItsClass) {
  auto view = OpenDefaultTable();
  ASSERT_TRUE(view.ok());
  auto index = std::make_unique<LineDirectionIndex>();
  ASSERT_TRUE(index->Build(*view, kAngleCutMm2));
  const uint32_t bins = view->line_grid().bin_count(), n = view->line_entry_count();
  std::vector<int> seen(n, 0);
  for (int c = 0; c < LineDirectionIndex::kClasses; ++c) {
    for (uint32_t b = 0; b < bins; ++b) {
      uint32_t previous = 0;
      for (uint32_t i = index->begin(c, b); i < index->end(c, b); ++i) {
        const LineDirectionIndex::Entry& d = index->entry(i);
        ASSERT_LT(d.table_index, n);
        // In bin b of the table, after the entry before it.
        EXPECT_GE(d.table_index, view->line_bin_offsets()[b]);
        EXPECT_LT(d.table_index, view->line_bin_offsets()[b + 1]);
        if (i > index->begin(c, b)) {
          EXPECT_GT(d.table_index, previous);
        }
        previous = d.table_index;
        EXPECT_EQ(LineDirectionIndex::ClassOf({d.ux, d.uy, d.uz}), c);
        const LineDirectionIndex::Entry decoded =
            DecodeLineEntry(view->line_entries()[d.table_index], d.table_index);
        const float want[] = {decoded.ux, decoded.uy, decoded.uz, decoded.length_mm,
                              decoded.cx, decoded.cy, decoded.cz};
        const float got[] = {d.ux, d.uy, d.uz, d.length_mm, d.cx, d.cy, d.cz};
        for (int k = 0; k < 7; ++k) EXPECT_EQ(got[k], want[k]) << "entry " << d.table_index;
        ++seen[d.table_index];
      }
    }
  }
  for (uint32_t e = 0; e < n; ++e) EXPECT_EQ(seen[e], 1) << "entry " << e;
}

// A row of bins is visited only for the classes ClassesIn names: it must name every class with
// an entry in the range, and no other.
TEST(LineDirectionIndex, ClassesInNamesTheClassesWithEntriesInTheBins) {
  auto view = OpenDefaultTable();
  ASSERT_TRUE(view.ok());
  auto index = std::make_unique<LineDirectionIndex>();
  ASSERT_TRUE(index->Build(*view, kAngleCutMm2));
  const uint32_t bins = view->line_grid().bin_count();
  std::mt19937 rng(11);
  int empty = 0, held = 0;
  for (int trial = 0; trial < 4000; ++trial) {
    // Single bins and short ranges, as the rows of a look-up's ball.
    const uint32_t lo = rng() % bins;
    const uint32_t hi = std::min(bins - 1, lo + (trial % 2 == 0 ? 0u : uint32_t(rng() % 8)));
    const uint64_t classes = index->ClassesIn(lo, hi);
    for (int c = 0; c < LineDirectionIndex::kClasses; ++c) {
      const bool has_entries = index->begin(c, lo) < index->end(c, hi);
      ASSERT_EQ(((classes >> c) & 1u) != 0, has_entries)
          << "class " << c << ", bins " << lo << ".." << hi;
      (has_entries ? held : empty) += 1;
    }
  }
  // Both kinds occur: the mask does leave classes out, and names others.
  EXPECT_GT(empty, 0);
  EXPECT_GT(held, 0);
}

TEST(LineDirectionIndex, SkipsOnlyClassesWhoseEntriesFailTheAngleTest) {
  auto view = OpenDefaultTable();
  ASSERT_TRUE(view.ok());
  auto index = std::make_unique<LineDirectionIndex>();
  ASSERT_TRUE(index->Build(*view, kAngleCutMm2));
  const uint32_t bins = view->line_grid().bin_count();
  std::mt19937 rng(7);
  int skipped = 0;
  for (int trial = 0; trial < 2000; ++trial) {
    // Random directions, and directions close to entries' own (where classes are live).
    Eigen::Vector3f v = RandomUnit(rng);
    if (trial % 2 == 1) {
      const LineDirectionIndex::Entry& d = index->entry(rng() % view->line_entry_count());
      v = (Eigen::Vector3f(d.ux, d.uy, d.uz) + 0.1f * RandomUnit(rng)).normalized();
    }
    const uint64_t live = index->LiveClasses(v);
    for (int c = 0; c < LineDirectionIndex::kClasses; ++c) {
      if ((live >> c) & 1u) continue;
      for (uint32_t i = index->begin(c, 0); i < index->end(c, bins - 1); ++i) {
        const LineDirectionIndex::Entry& d = index->entry(i);
        const float cos_angle = v.dot(Eigen::Vector3f(d.ux, d.uy, d.uz));
        ASSERT_GE(d.length_mm * d.length_mm * (1.0f - cos_angle * cos_angle), kAngleCutMm2)
            << "class " << c << " skipped, entry " << d.table_index << " passes";
        ++skipped;
      }
    }
  }
  EXPECT_GT(skipped, 0);  // the index does skip entries
}

TEST(LineDirectionIndex, TooLargeATableIsNotIndexed) {
  auto view = OpenDefaultTable();
  ASSERT_TRUE(view.ok());
  auto index = std::make_unique<LineDirectionIndex>();
  EXPECT_TRUE(index->Build(*view, kAngleCutMm2));
  index->Clear();
  EXPECT_FALSE(index->built());
  // Line bins of 5 mm instead of 10: eight times the bins, more than kMaxBins.
  std::vector<Model> models;
  ASSERT_TRUE(LoadModelFolder("models", &models).ok());
  TableBuildOptions options;
  options.line_bin_mm = 5.0f;
  auto blob = BuildTableBlob(models, options);
  ASSERT_TRUE(blob.ok());
  std::vector<uint64_t> aligned(blob->size() / 8 + 1);
  std::memcpy(aligned.data(), blob->data(), blob->size());
  auto fine = TableView::Open(aligned.data(), blob->size());
  ASSERT_TRUE(fine.ok());
  ASSERT_GT(fine->line_grid().bin_count(), LineDirectionIndex::kMaxBins);
  EXPECT_TRUE(index->Build(*view, kAngleCutMm2));
  EXPECT_FALSE(index->Build(*fine, kAngleCutMm2));
  EXPECT_FALSE(index->built());
  // The recogniser searches such a table without the index.
  auto recognizer = MakeRecognizer(*fine);
  auto synthetic = std::make_unique<SyntheticScene>();
  SyntheticSceneParams p;
  p.min_objects = p.max_objects = 2;
  p.total_features = 100;
  GenerateSyntheticScene(ModelsOf(*fine), p, 3, synthetic.get());
  SceneSupportVerifier verifier;
  Vector<RecognizedObject, kMaxObjects> objects;
  ASSERT_TRUE(recognizer->Recognize(synthetic->scene, verifier, Budget{}, objects).ok());
  EXPECT_GE(objects.size(), 1u);
}

// The index changes which entries are visited, never a vote: every scene basis of cluttered
// scenes gives the same hypotheses with and without it (bit for bit on x86-64, see below).
TEST(LineDirectionIndex, VotesAreThoseOfTheFullLookUp) {
  for (int hf : {3, 5}) {
    auto table = BuildTable(static_cast<HashFunction>(hf));
    const std::vector<Model> models = ModelsOf(table->view);
    RecognizerConfig plain_config;
    plain_config.line_direction_index = false;
    auto indexed = MakeRecognizer(table->view);
    auto plain = MakeRecognizer(table->view, plain_config);
    auto synthetic = std::make_unique<SyntheticScene>();
    SyntheticSceneParams p;
    p.total_features = 400;
    int compared = 0;
    for (uint64_t seed = 1; seed <= 3; ++seed) {
      GenerateSyntheticScene(models, p, seed, synthetic.get());
      indexed->PrepareScene(synthetic->scene);
      plain->PrepareScene(synthetic->scene);
      ASSERT_EQ(indexed->CandidateCount(), plain->CandidateCount());
      const uint32_t n = std::min<uint32_t>(indexed->CandidateCount(), 150);
      for (uint32_t i = 0; i < n; ++i) {
        Vector<Hypothesis, kMaxHypothesesPerBasis> a, b;
        float best_a[kMaxTableModels], best_b[kMaxTableModels];
        const int na = indexed->VoteForBasis(indexed->Candidate(i), a, best_a);
        const int nb = plain->VoteForBasis(plain->Candidate(i), b, best_b);
        ASSERT_EQ(na, nb) << "hf " << hf << " seed " << seed << " basis " << i;
        // Votes bit for bit where multiply and add round apart (x86-64); where the compiler
        // fuses them (aarch64) the two look-ups' sums may round apart by a few millionths (one
        // entry's weight rounded once less).
        const auto close = [](float x, float y) { return std::abs(x - y) <= 1e-5f; };
        for (uint32_t m = 0; m < kMaxTableModels; ++m) {
          EXPECT_TRUE(close(best_a[m], best_b[m]))
              << "model " << m << ": " << best_a[m] << " " << best_b[m];
        }
        for (int h = 0; h < na; ++h) {
          EXPECT_EQ(a[h].model, b[h].model);
          EXPECT_EQ(a[h].model_basis, b[h].model_basis);
          EXPECT_TRUE(close(a[h].vote, b[h].vote)) << a[h].vote << " " << b[h].vote;
          EXPECT_TRUE(a[h].cam_T_model.R == b[h].cam_T_model.R);
          EXPECT_TRUE(a[h].cam_T_model.t_mm == b[h].cam_T_model.t_mm);
        }
        compared += na;
      }
    }
    EXPECT_GT(compared, 0) << "hf " << hf;
  }
}

}  // namespace
}  // namespace sh
