// Single-colour parts through the firmware: a model set whose SHAPE_VIEWS section gives the
// board's recognition the colour path, the simulated world drawing the parts in their MTL colour
// and its cameras delivering NV12 frames, the parts in the CAN result sets at the simulator's
// truth with their model ids, the model mask selecting them like any model, and the per-frame
// path with colour frames allocating nothing (this binary counts every operator new).
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <Eigen/Geometry>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "firmware/pipeline_recognition.hpp"
#include "firmware/truth_recognition.hpp"
#include "recog/geometry/rigid_transform.hpp"
#include "tables/model_files.hpp"
#include "tests/support/aligned_blob.hpp"
#include "tests/support/clock_standing_still.hpp"
#include "tests/support/counting_allocator.hpp"
#include "tests/support/firmware_doubles.hpp"
#include "tests/support/sim_scene_observer.hpp"
#include "tests/support/sim_world_once.hpp"
#include "tests/support/tool_run.hpp"
#include "tools/tablegen/model_set_writer.hpp"
#include "tools/tablegen/shape_view_builder.hpp"

namespace sh::testing {
namespace {

const std::string kColourModels = std::string(STEREOHASH_FW_SOURCE_MODELS_DIR) + "/colour";
constexpr const char* kParts[] = {"cube", "can"};  // model ids 0 and 1 of the set

// A model set of the red cube and the red can of models/colour (SHAPE_VIEWS only: no polyhedra),
// and a folder with the same two parts (OBJ + MTL) for the simulated world.
struct Files {
  ~Files() { (void)std::system(("rm -rf " + dir).c_str()); }
  std::string dir, set, parts_dir;
  std::vector<uint8_t> views;
};

const Files& TestFiles() {
  static const std::unique_ptr<Files> files = [] {
    auto f = std::make_unique<Files>();
    char dir[] = "/tmp/stereohash_colour_XXXXXX";
    EXPECT_NE(mkdtemp(dir), nullptr);
    f->dir = dir;
    f->parts_dir = f->dir + "/parts";
    EXPECT_EQ(mkdir(f->parts_dir.c_str(), 0700), 0);
    std::vector<ShapeModelInput> inputs;
    std::string manifest;
    for (const char* name : kParts) {
      const std::string obj = kColourModels + "/" + name + ".obj";
      for (const char* ext : {".obj", ".mtl"}) {
        const std::string text = ReadFileText(kColourModels + "/" + name + ext);
        EXPECT_FALSE(text.empty()) << name << ext;
        EXPECT_TRUE(WriteTestFile(f->parts_dir + "/" + name + ext, text.data(), text.size()));
      }
      manifest += std::string(name) + "\n";
      Result<Model> m = LoadModelFile(obj);
      EXPECT_TRUE(m.ok()) << m.status().message();
      if (!m.ok()) continue;
      ShapeModelInput in;
      in.model = *m;
      EXPECT_TRUE(LoadModelColour(obj, in.model, in.kd).ok());
      inputs.push_back(in);
    }
    EXPECT_TRUE(WriteTestFile(f->parts_dir + "/models.txt", manifest.data(), manifest.size()));
    ShapeViewBuildOptions options;  // fewer components and PCA views: quick under qemu
    options.n_components = 60;
    options.pca_views = 1500;
    Result<std::vector<uint8_t>> views = BuildShapeViewBlob(inputs, options);
    EXPECT_TRUE(views.ok()) << views.status().message();
    if (views.ok()) f->views = *views;
    Result<std::vector<uint8_t>> set =
        BuildModelSet({{uint32_t(SectionKind::kShapeViews), f->views.data(), f->views.size()}});
    EXPECT_TRUE(set.ok()) << set.status().message();
    f->set = f->dir + "/colour.bin";
    if (set.ok()) {
      EXPECT_TRUE(WriteTestFile(f->set, set->data(), set->size()));
    }
    return f;
  }();
  return *files;
}

// Position error at the corner centroid (which the symmetries fix) and rotation error modulo the
// model's symmetries.
bool Matches(const ObjectPose& p, const Model& model, const RigidTransform& truth) {
  const Eigen::Quaternionf q(
      static_cast<float>(p.cam_q_model[0]), static_cast<float>(p.cam_q_model[1]),
      static_cast<float>(p.cam_q_model[2]), static_cast<float>(p.cam_q_model[3]));
  RigidTransform got;
  got.R = q.normalized().toRotationMatrix();
  got.t_mm = Eigen::Vector3f(static_cast<float>(p.cam_t_model_mm[0]),
                             static_cast<float>(p.cam_t_model_mm[1]),
                             static_cast<float>(p.cam_t_model_mm[2]));
  Eigen::Vector3f centroid = Eigen::Vector3f::Zero();
  for (int c = 0; c < model.n_corners; ++c) centroid += model.corner(c) / float(model.n_corners);
  float angle = 180.0f;
  for (int k = 0; k < model.n_symmetries; ++k) {
    angle = std::min(angle, RotationAngleDeg(got.R.transpose() * truth.R * model.symmetry(k)));
  }
  return ((got * centroid) - (truth * centroid)).norm() < 5.0f && angle < 5.0f;
}

struct Score {
  int truth = 0, found = 0, false_alarms = 0;
};

// Scored with the set's models, which carry the symmetry groups (the world's do not).
void ScoreSet(const render::SimWorld& world, const ModelSet& models, const int* ids, int scene,
              const ResultSet& set, Score* score) {
  const render::GeneratedScene& g = world.scene(scene);
  std::vector<bool> used(g.scene.objects.size(), false);
  for (int i = 0; i < set.object_count; ++i) {
    const ObjectPose& p = set.objects[i];
    bool matched = false;
    for (size_t k = 0; k < g.scene.objects.size() && !matched; ++k) {
      const int model = g.scene.objects[k].model_index;
      if (used[k] || ids[model] != p.model_id) continue;
      matched = Matches(p, models.model(uint32_t(ids[model])), g.left_T_model[k]);
      used[k] = matched;
    }
    score->found += matched;
    score->false_alarms += !matched;
  }
  score->truth += static_cast<int>(g.scene.objects.size());
}

TEST(FirmwareColour, PartsInResultSetsAtTheirTruthFromNv12FramesWithoutTouchingTheHeap) {
  const Files& files = TestFiles();
  ASSERT_FALSE(files.views.empty());
  // Both parts red: colour alone never decides the model.
  static render::SimWorld world;
  render::SimWorldConfig wc;
  wc.models_dir = files.parts_dir.c_str();  // the parts are the world's models, painted
  wc.scenes = 3;
  wc.objects = 2;
  wc.seed = 11;
  ASSERT_TRUE(BuildOnce(world, wc));
  ASSERT_TRUE(world.colour());

  PlcBus can;
  hal::SimCanEndpoint* plc = can.plc;
  hal::SimGpio gpio;
  hal::SimCamera camera(&world, hal::SimCameraConfig{});
  FileDataSource data(files.set.c_str(), "", &world.calibration());
  static Pipeline pipeline;
  PipelineRecognition recognition({&pipeline}, WithClockStandingStill());
  SceneObserver observer(&world);
  CoreConfig config;
  config.node_id = 1;
  config.heartbeat_ms = 50;
  config.capture_timeout_ms = 2000;
  config.budget_ms = kTimeBudgetMinMs;  // never reached: the recogniser's clock stands still
  const CoreDevices devices =
      SimCoreDevices(can.fw, &gpio, &camera, &recognition, &data, &observer);
  static FirmwareCore core;
  ASSERT_TRUE(core.Start(config, devices).ok());
  ASSERT_EQ(core.state(), FirmwareState::kReady);
  ASSERT_EQ(core.loaded_models(), 2u);  // the set's colour parts alone, no polyhedra
  EXPECT_EQ(core.model_mask(), 0x3u);

  const AlignedBlob blob(files.views);
  const Result<ShapeViewsView> views = ShapeViewsView::Open(blob.data, blob.size);
  ASSERT_TRUE(views.ok()) << views.status().message();
  const ModelSet models(nullptr, &*views);
  int ids[render::kMaxWorldModels] = {};
  MapWorldModelsToIds(world, models, ids);
  EXPECT_EQ(ids[0], 0);
  EXPECT_EQ(ids[1], 1);

  ResultAssembler assembler(1);
  auto run_trigger = [&](uint8_t request, ResultSet* set, int* scene) {
    if (!plc->Send(TriggerFrame(1, request)).ok() || !WaitResultSet(plc, &assembler, set, 12000))
      return false;
    *scene = observer.SceneOf(set->sequence);
    return *scene >= 0;
  };
  static ResultSet set;
  Score all;
  for (uint8_t i = 0; i < 3; ++i) {
    int scene = -1;
    ASSERT_TRUE(run_trigger(uint8_t(1 + i), &set, &scene));
    ScoreSet(world, models, ids, scene, set, &all);
  }
  std::printf("colour parts: %d of %d found within 5 mm / 5 deg, %d false\n", all.found, all.truth,
              all.false_alarms);
  EXPECT_EQ(all.truth, 6);
  EXPECT_GE(all.found, all.truth - 1);
  EXPECT_EQ(all.false_alarms, 0);
  EXPECT_EQ(observer.colour_frames(), 3);

  // The can alone (id 1): only cans reported; allocation-free from here on.
  const uint64_t allocations_before = HeapAllocations();
  ASSERT_TRUE(plc->Send(SelectModelsFrame(1, 0x2u)).ok());
  for (int i = 0; i < 2000 && core.model_mask() != 0x2u; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  ASSERT_EQ(core.model_mask(), 0x2u);
  int cans = 0;
  for (uint8_t i = 0; i < 3; ++i) {
    int scene = -1;
    ASSERT_TRUE(run_trigger(uint8_t(10 + i), &set, &scene));
    for (int k = 0; k < set.object_count; ++k) EXPECT_EQ(set.objects[k].model_id, 1);
    cans += set.object_count;
  }
  EXPECT_GE(cans, 2);
  const uint64_t allocations = HeapAllocations() - allocations_before;
  core.Stop();
  EXPECT_EQ(allocations, 0u) << "heap allocations during 3 triggers with colour parts";
}

}  // namespace
}  // namespace sh::testing
