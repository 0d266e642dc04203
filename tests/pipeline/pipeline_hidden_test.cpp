// Polyhedra among printed cartons (the simulated world draws the cartons with their artwork):
// the cartons' box edges, corners and the print's straight lines flood the polyhedral path's
// features and search. Handed to Process() as found objects (here at their true poses, as the
// texture path finds them to about a millimetre), their silhouettes are hidden from it, and it
// finds polyhedra it otherwise misses. Also: nothing inside the hidden silhouettes reaches the
// features, and the hidden path allocates nothing (this binary counts operator new).
#include <gtest/gtest.h>

#include <atomic>
#include <memory>
#include <vector>

#include "hal/sim/world/sim_world.hpp"
#include "recog/pipeline/pipeline.hpp"
#include "tables/table_file.hpp"
#include "tests/support/counting_allocator.hpp"
#include "tools/eval/rendered_eval.hpp"

namespace sh {
namespace {

int64_t FakeClock() {
  // Called from the pipeline's worker threads too: one atomic count.
  static std::atomic<int64_t> t{0};
  return t += 1000;  // 1 us per call: the budget is never reached
}

struct MixedScene {
  std::vector<uint8_t> left, right;
  std::vector<TruthObject> polyhedra;  // table model ids
  std::vector<PosedModel> cartons;     // at their true poses
};

// Scenes of four objects, polyhedra and cartons, on the dark table.
class PipelineHidden : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    Result<TableView> t = OpenDefaultTable();
    ASSERT_TRUE(t.ok()) << t.status().message();
    table_ = new TableView(*t);
    models_ = new RenderModels();
    ASSERT_TRUE(LoadRenderModels(STEREOHASH_MODELS_DIR, *table_, models_).ok());
    world_ = new render::SimWorld();
    render::SimWorldConfig wc;
    wc.models_dir = STEREOHASH_MODELS_DIR;
    wc.printed_dir = STEREOHASH_MODELS_DIR "/textured";
    wc.seed = 7;
    wc.scenes = kScenes;
    wc.objects = 4;
    const Status built = world_->Build(wc);
    ASSERT_TRUE(built.ok()) << built.message();
    scenes_ = new std::vector<MixedScene>(kScenes);
    const CameraIntrinsics& cam = world_->calibration().left;
    for (int i = 0; i < kScenes; ++i) {
      MixedScene& s = (*scenes_)[size_t(i)];
      s.left.resize(size_t(cam.width) * cam.height);
      s.right.resize(s.left.size());
      ASSERT_TRUE(world_
                      ->Render(uint64_t(i),
                               GrayView{s.left.data(), cam.width, cam.height, cam.width},
                               GrayView{s.right.data(), cam.width, cam.height, cam.width})
                      .ok());
      const render::GeneratedScene& g = world_->scene(i);
      for (size_t k = 0; k < g.scene.objects.size(); ++k) {
        const int m = g.scene.objects[k].model_index;
        if (world_->is_printed(m)) {
          s.cartons.push_back({&world_->models()[m], g.left_T_model[k]});
        } else {
          const int id = table_->FindModel(world_->models()[m].name);
          if (id >= 0) s.polyhedra.push_back({id, g.left_T_model[k]});
        }
      }
    }
    pipeline_ = new Pipeline();
    // On the calling thread: the threaded composition of cartons and polyhedra runs under
    // ThreadSanitizer in fw_printed_test, and one thread gives what several give
    // (pipeline_test's SearchOnMoreThreadsGivesWhatOneGives).
    PipelineConfig config = PipelineConfig::Automatic();
    config.threads = 1;
    ASSERT_TRUE(pipeline_->Init(world_->calibration(), *table_, config, FakeClock).ok());
  }
  static void TearDownTestSuite() {
    delete pipeline_;
    delete scenes_;
    delete world_;
    delete models_;
    delete table_;
  }

  ConstGrayView View(const std::vector<uint8_t>& pixels) const {
    const CameraIntrinsics& cam = world_->calibration().left;
    return {pixels.data(), cam.width, cam.height, cam.width};
  }

  static constexpr int kScenes = 8;
  static TableView* table_;
  static RenderModels* models_;
  static render::SimWorld* world_;
  static std::vector<MixedScene>* scenes_;
  static Pipeline* pipeline_;
};

TableView* PipelineHidden::table_ = nullptr;
RenderModels* PipelineHidden::models_ = nullptr;
render::SimWorld* PipelineHidden::world_ = nullptr;
std::vector<MixedScene>* PipelineHidden::scenes_ = nullptr;
Pipeline* PipelineHidden::pipeline_ = nullptr;

TEST_F(PipelineHidden, FindsPolyhedraAmongCartonsOnlyWithTheirSilhouettesHidden) {
  static PipelineResult result;
  int truth = 0, cartons = 0, found_plain = 0, found_hidden = 0, false_hidden = 0;
  for (const MixedScene& s : *scenes_) {
    truth += int(s.polyhedra.size());
    cartons += int(s.cartons.size());
    ASSERT_TRUE(pipeline_->Process(View(s.left), View(s.right), 0, &result).ok());
    found_plain += MatchToTruth(models_->table, s.polyhedra, PosesOf(result)).correct;
    ASSERT_TRUE(
        pipeline_
            ->Process(View(s.left), View(s.right), 0, &result, s.cartons.data(), s.cartons.size())
            .ok());
    EXPECT_EQ(result.hidden_objects, s.cartons.size());
    EXPECT_EQ(result.hidden_not_masked, 0u);
    const MatchCounts m = MatchToTruth(models_->table, s.polyhedra, PosesOf(result));
    found_hidden += m.correct;
    false_hidden += m.false_alarms;
  }
  std::printf(
      "%d polyhedra among %d cartons: %d found as they are, %d with the cartons hidden "
      "(%d false)\n",
      truth, cartons, found_plain, found_hidden, false_hidden);
  ASSERT_GT(cartons, truth / 2);  // the scenes do mix them
  // Measured: 0 of 18 found as they are, 15 with the cartons hidden, 2 false alarms (the
  // polyhedral path's own rate on the table, docs/texture.md).
  EXPECT_GE(found_hidden, found_plain + 6);
  EXPECT_GE(found_hidden * 10, truth * 7);
  EXPECT_LE(false_hidden, 3);
}

TEST_F(PipelineHidden, NothingInsideAHiddenSilhouetteReachesTheFeatures) {
  static PipelineResult result;
  const MixedScene& s = (*scenes_)[0];
  ASSERT_FALSE(s.cartons.empty());
  ASSERT_TRUE(
      pipeline_
          ->Process(View(s.left), View(s.right), 0, &result, s.cartons.data(), s.cartons.size())
          .ok());
  const ViewCamera views[2] = {LeftView(world_->calibration()), RightView(world_->calibration())};
  static HiddenMask mask[2];
  for (int i = 0; i < 2; ++i) {
    mask[i].Clear();
    for (const PosedModel& c : s.cartons) {
      ASSERT_TRUE(mask[i].Add(views[i], c, PipelineConfig::Automatic().hide_margin_px));
    }
    EXPECT_GT(result.masked_edge_pixels[i], 1000u) << "image " << i;
    EXPECT_GT(result.masked_corners[i], 0u) << "image " << i;
    const ImageFeatures& f = i == 0 ? pipeline_->left_features() : pipeline_->right_features();
    for (const Corner2D& c : f.corners) EXPECT_FALSE(mask[i].Hides(c.x_px, c.y_px));
    const ConstEdgeMapView edges = i == 0 ? pipeline_->left_edges() : pipeline_->right_edges();
    int inside = 0;
    for (int y = 0; y < edges.edge.height; ++y) {
      for (int x = 0; x < edges.edge.width; ++x) {
        inside += edges.edge.at(x, y) != 0 && mask[i].Hides(float(x), float(y));
      }
    }
    EXPECT_EQ(inside, 0) << "image " << i;
    for (const Line2D& l : f.lines) {
      for (const Segment2D& seg : l.segments) {
        const float mx = 0.5f * (seg.x0 + seg.x1), my = 0.5f * (seg.y0 + seg.y1);
        EXPECT_FALSE(mask[i].Hides(mx, my) && mask[i].Hides(seg.x0, seg.y0) &&
                     mask[i].Hides(seg.x1, seg.y1));
      }
    }
  }
}

TEST_F(PipelineHidden, NoAllocationWithHiddenObjects) {
  static PipelineResult result;
  size_t found = 0;
  const uint64_t before = testing::HeapAllocations();
  for (const MixedScene& s : *scenes_) {
    ASSERT_TRUE(pipeline_
                    ->Process(View(s.left), View(s.right), 1000.0f, &result, s.cartons.data(),
                              s.cartons.size())
                    .ok());
    found += result.objects.size();
  }
  EXPECT_EQ(testing::HeapAllocations() - before, 0u) << "heap allocations while processing";
  EXPECT_GT(found, 0u);
}

}  // namespace
}  // namespace sh
