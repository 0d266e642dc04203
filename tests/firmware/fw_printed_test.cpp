// Printed cartons through the firmware: a feature database loaded beside the hash tables (the
// `features` key), the simulated world placing printed cartons drawn with their artwork, the
// texture path in the board's recognition, and the cartons in the CAN result sets at the
// simulator's truth with their model ids (after the tables' polyhedra); the model mask selects
// them like any model; a damaged or missing database is a data fault (EMCY 0x6300) with the
// heartbeat going on; and the per-frame path with cartons allocates nothing (this binary counts
// every operator new).
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
#include "hal/sim/textured_model_files.hpp"
#include "recog/geometry/rigid_transform.hpp"
#include "tests/support/aligned_blob.hpp"
#include "tests/support/clock_standing_still.hpp"
#include "tests/support/counting_allocator.hpp"
#include "tests/support/firmware_doubles.hpp"
#include "tests/support/sim_scene_observer.hpp"
#include "tests/support/sim_world_once.hpp"
#include "tests/support/temp_dir.hpp"
#include "tools/tablegen/feature_db_builder.hpp"
#include "tools/tablegen/model_set_writer.hpp"

namespace sh::testing {
namespace {

const std::string kModels = STEREOHASH_FW_SOURCE_MODELS_DIR;

bool WriteFile(const std::string& path, const std::vector<uint8_t>& bytes) {
  return WriteTestFile(path, bytes.data(), bytes.size());
}

bool CopyFile(const std::string& from, const std::string& to) {
  std::FILE* in = std::fopen(from.c_str(), "rb");
  if (in == nullptr) return false;
  std::vector<uint8_t> bytes;
  uint8_t buffer[4096];
  size_t n;
  while ((n = std::fread(buffer, 1, sizeof(buffer), in)) > 0)
    bytes.insert(bytes.end(), buffer, buffer + n);
  std::fclose(in);
  return WriteFile(to, bytes);
}

// The four cartons of models/textured learnt into a feature database file, a damaged copy
// (one flipped byte in the middle), and a folder of plain models holding the cube only, so that
// every scene of five objects shows the cube and all four cartons.
struct Files {
  sh::testing::TempDir temp{"printed"};
  std::string dir = temp.path();
  std::string features, damaged, plain_dir;
  std::vector<uint8_t> blob;
  // One model set holding the default hash tables and the cartons' database, and a copy of it
  // with one flipped byte in the database's section.
  std::string set, damaged_set;
  std::vector<uint8_t> set_blob;
};

const Files& TestFiles() {
  static const std::unique_ptr<Files> files = [] {
    auto f = std::make_unique<Files>();
    EXPECT_TRUE(f->temp.ok());
    std::vector<TexturedModel> printed;
    for (const char* name : {"cereal", "pills", "tea", "tools"}) {
      Result<TexturedModel> m = LoadTexturedModelFile(kModels + "/textured/" + name + ".obj");
      EXPECT_TRUE(m.ok()) << m.status().message();
      if (m.ok()) printed.push_back(std::move(*m));
    }
    Result<std::vector<uint8_t>> blob = BuildFeatureDb(printed, FeatureDbBuildOptions{});
    EXPECT_TRUE(blob.ok()) << blob.status().message();
    if (blob.ok()) f->blob = *blob;
    f->features = f->dir + "/cartons.bin";
    f->damaged = f->dir + "/damaged.bin";
    EXPECT_TRUE(WriteFile(f->features, f->blob));
    std::vector<uint8_t> damaged = f->blob;
    if (!damaged.empty()) damaged[damaged.size() / 2] ^= 0x5A;
    EXPECT_TRUE(WriteFile(f->damaged, damaged));
    Result<std::vector<uint8_t>> set =
        BuildModelSet({{uint32_t(SectionKind::kHash3d),
                        static_cast<const uint8_t*>(DefaultTableBlob()), DefaultTableBlobSize()},
                       {uint32_t(SectionKind::kTextureFeatures), f->blob.data(), f->blob.size()}});
    EXPECT_TRUE(set.ok()) << set.status().message();
    if (set.ok()) f->set_blob = *set;
    f->set = f->dir + "/models.bin";
    f->damaged_set = f->dir + "/damaged_models.bin";
    EXPECT_TRUE(WriteFile(f->set, f->set_blob));
    std::vector<uint8_t> damaged_set = f->set_blob;
    if (!damaged_set.empty()) damaged_set[damaged_set.size() - f->blob.size() / 2] ^= 0x5A;
    EXPECT_TRUE(WriteFile(f->damaged_set, damaged_set));
    f->plain_dir = f->dir + "/plain";
    EXPECT_EQ(mkdir(f->plain_dir.c_str(), 0700), 0);
    EXPECT_TRUE(CopyFile(kModels + "/cube.obj", f->plain_dir + "/cube.obj"));
    return f;
  }();
  return *files;
}

float AngleDeg(const ObjectPose& p, const RigidTransform& truth) {
  const Eigen::Quaternionf q(
      static_cast<float>(p.cam_q_model[0]), static_cast<float>(p.cam_q_model[1]),
      static_cast<float>(p.cam_q_model[2]), static_cast<float>(p.cam_q_model[3]));
  return RotationAngleDeg(q.normalized().toRotationMatrix().transpose() * truth.R);
}

float DistanceMm(const ObjectPose& p, const RigidTransform& truth) {
  const Eigen::Vector3f t(static_cast<float>(p.cam_t_model_mm[0]),
                          static_cast<float>(p.cam_t_model_mm[1]),
                          static_cast<float>(p.cam_t_model_mm[2]));
  return (t - truth.t_mm).norm();
}

// Cartons of one set against the truth of its scene (5 mm, 5 degrees, same model id).
struct Score {
  int truth = 0, found = 0, reported = 0, false_alarms = 0, polyhedra = 0;
};

void ScoreSet(const render::SimWorld& world, const int* ids, int scene, const ResultSet& set,
              Score* score) {
  const render::GeneratedScene& g = world.scene(scene);
  for (int i = 0; i < set.object_count; ++i) {
    const ObjectPose& p = set.objects[i];
    bool printed = false, matches = false;
    for (size_t k = 0; k < g.scene.objects.size(); ++k) {
      const int model = g.scene.objects[k].model_index;
      if (!world.is_printed(model) || ids[model] != p.model_id) continue;
      printed = true;
      matches |= DistanceMm(p, g.left_T_model[k]) < 5.0f && AngleDeg(p, g.left_T_model[k]) < 5.0f;
    }
    if (!printed && p.model_id < 6) {
      ++score->polyhedra;
      continue;
    }
    ++score->reported;
    score->false_alarms += !matches;
  }
  for (size_t k = 0; k < g.scene.objects.size(); ++k) {
    const int model = g.scene.objects[k].model_index;
    if (!world.is_printed(model)) continue;
    ++score->truth;
    bool found = false;
    for (int i = 0; i < set.object_count; ++i) {
      const ObjectPose& p = set.objects[i];
      found |= p.model_id == ids[model] && DistanceMm(p, g.left_T_model[k]) < 5.0f &&
               AngleDeg(p, g.left_T_model[k]) < 5.0f;
    }
    score->found += found;
  }
}

// The cube and the four cartons, five objects in each of `scenes` scenes.
::testing::AssertionResult BuildCartonWorld(const Files& files, int scenes,
                                            render::SimWorld* world) {
  render::SimWorldConfig wc;
  wc.models_dir = files.plain_dir.c_str();
  wc.printed_dir = "models/textured";
  wc.scenes = scenes;
  wc.objects = 5;
  return BuildOnce(*world, wc);
}

CoreConfig CartonCoreConfig() {
  CoreConfig config;
  config.node_id = 1;
  config.heartbeat_ms = 50;
  config.capture_timeout_ms = 2000;
  config.budget_ms = kTimeBudgetMinMs;  // never reached: the recogniser's clock stands still
  return config;
}

TEST(FirmwarePrinted, CartonsInResultSetsAtTheirTruthWithIdsAfterThePolyhedra) {
  const Files& files = TestFiles();
  ASSERT_FALSE(files.blob.empty());
  static render::SimWorld world;
  ASSERT_TRUE(BuildCartonWorld(files, 3, &world));
  ASSERT_EQ(world.model_count(), 5);

  PlcBus can;
  hal::SimCanEndpoint* fw = can.fw;
  hal::SimCanEndpoint* plc = can.plc;
  hal::SimGpio gpio;
  hal::SimCamera camera(&world, hal::SimCameraConfig{});
  FileDataSource data("builtin", "", &world.calibration());
  data.SetFeaturesPath(files.features.c_str());
  static Pipeline pipeline;
  static texture::TextureRecognizer texture;
  static texture::TextureResult texture_result;
  PipelineRecognition recognition({&pipeline, &texture, &texture_result}, WithClockStandingStill());
  SceneObserver observer(&world);
  const CoreConfig config = CartonCoreConfig();
  const CoreDevices devices = SimCoreDevices(fw, &gpio, &camera, &recognition, &data, &observer);
  static FirmwareCore core;
  ASSERT_TRUE(core.Start(config, devices).ok());
  ASSERT_EQ(core.state(), FirmwareState::kReady);
  // The default tables' six polyhedra, then the four cartons.
  ASSERT_EQ(core.loaded_models(), 10u);
  EXPECT_EQ(core.model_mask(), 0x3FFu);

  // Model id of each world model from the same data (not through the data source: loading again
  // would replace the firmware's mapping).
  const Result<TableView> table = OpenDefaultTable();
  const AlignedBlob blob(files.blob);
  const Result<FeatureDbView> db = FeatureDbView::Open(blob.data, blob.size);
  ASSERT_TRUE(table.ok() && db.ok());
  const ModelSet models(&*table, nullptr, &*db);
  int ids[render::kMaxWorldModels] = {};
  MapWorldModelsToIds(world, models, ids);
  for (int m = 0; m < world.model_count(); ++m) {
    EXPECT_EQ(world.is_printed(m), ids[m] >= 6) << world.models()[m].name;
    EXPECT_GE(ids[m], 0) << world.models()[m].name;
  }

  ResultAssembler assembler(1);
  // Up to 120 s per set (qemu).
  auto wait_set = [&](ResultSet* out) { return WaitResultSet(plc, &assembler, out, 12000); };
  auto run_trigger = [&](uint8_t request, ResultSet* set, int* scene) {
    if (!plc->Send(TriggerFrame(1, request)).ok() || !wait_set(set)) return false;
    *scene = observer.SceneOf(set->sequence);
    return *scene >= 0;
  };
  auto select_models = [&](uint32_t mask) {
    ASSERT_TRUE(plc->Send(SelectModelsFrame(1, mask)).ok());
    for (int i = 0; i < 2000 && core.model_mask() != mask; ++i) {
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    ASSERT_EQ(core.model_mask(), mask);
  };

  // Every scene once: the cartons at their truth, with their ids.
  static ResultSet set;
  Score all;
  for (uint8_t i = 0; i < 3; ++i) {
    int scene = -1;
    ASSERT_TRUE(run_trigger(uint8_t(1 + i), &set, &scene));
    ScoreSet(world, ids, scene, set, &all);
  }
  std::printf("cartons: %d of %d found within 5 mm / 5 deg, %d reported, %d false; %d polyhedra\n",
              all.found, all.truth, all.reported, all.false_alarms, all.polyhedra);
  EXPECT_EQ(all.truth, 12);  // four cartons in each of three scenes
  EXPECT_GE(all.found, all.truth - 1);
  EXPECT_EQ(all.false_alarms, 0);

  // The mask without the cartons' bits: no carton reported; allocation-free from here on (every
  // table and buffer exists after the first frames).
  const uint64_t allocations_before = HeapAllocations();
  select_models(0x3Fu);
  Score polyhedra_only;
  for (uint8_t i = 0; i < 3; ++i) {
    int scene = -1;
    ASSERT_TRUE(run_trigger(uint8_t(10 + i), &set, &scene));
    for (int k = 0; k < set.object_count; ++k) EXPECT_LT(set.objects[k].model_id, 6);
    ScoreSet(world, ids, scene, set, &polyhedra_only);
  }
  EXPECT_EQ(polyhedra_only.reported, 0);

  // Only two cartons (ids 6 and 8: cereal and tea): only they are reported.
  select_models((1u << 6) | (1u << 8));
  Score two;
  for (uint8_t i = 0; i < 3; ++i) {
    int scene = -1;
    ASSERT_TRUE(run_trigger(uint8_t(20 + i), &set, &scene));
    for (int k = 0; k < set.object_count; ++k) {
      EXPECT_TRUE(set.objects[k].model_id == 6 || set.objects[k].model_id == 8)
          << int(set.objects[k].model_id);
    }
    ScoreSet(world, ids, scene, set, &two);
  }
  EXPECT_GE(two.found, 5);  // of the six cartons of these two models in the three scenes
  EXPECT_EQ(two.false_alarms, 0);
  const uint64_t allocations = HeapAllocations() - allocations_before;
  core.Stop();
  EXPECT_EQ(allocations, 0u) << "heap allocations during 6 triggers with printed models";
}

TEST(FirmwarePrinted, DamagedOrMissingFeatureDatabaseIsADataFaultUntilReplaced) {
  const Files& files = TestFiles();
  ASSERT_FALSE(files.blob.empty());
  for (const std::string& path : {files.damaged, files.dir + "/missing.bin"}) {
    // The file the key names, damaged (or absent) at boot, then replaced by a good one.
    const std::string configured = files.dir + "/configured.bin";
    std::remove(configured.c_str());
    if (path == files.damaged) {
      ASSERT_TRUE(CopyFile(path, configured));
    }
    Rig rig;
    rig.data->SetFeaturesPath(configured.c_str());
    rig.Start();
    SCOPED_TRACE(path);
    rig.ExpectBootDataFault(kDetailFeatures);

    ASSERT_TRUE(WriteFile(configured, files.blob));
    rig.ClearFault();
    std::optional<CommandAck> ack = rig.WaitAck(0x04);
    ASSERT_TRUE(ack);
    EXPECT_EQ(ack->status, 0);
    EXPECT_TRUE(rig.WaitState(FirmwareState::kReady));
    EXPECT_EQ(rig.recognition.inits.load(), 1);
    EXPECT_EQ(rig.core.loaded_models(), 10u);
    rig.Trigger(7);
    EXPECT_TRUE(rig.WaitSet());
  }
}

// features_crc32 pins the features file: its header's CRC-32 loads, another is refused naming
// both values and the key, and a model set's own cartons (no features file) carry no pin.
TEST(FirmwarePrinted, AFeaturesFileOtherThanThePinnedOneIsRefused) {
  const Files& files = TestFiles();
  ASSERT_FALSE(files.blob.empty());
  const uint32_t crc = BlobHeaderCrc32(files.blob.data(), files.blob.size());
  const StereoCalibration calib;
  FileDataSource data("builtin", "", &calib);
  data.SetFeaturesPath(files.features.c_str());
  data.PinIdentity(0, crc);
  ASSERT_TRUE(data.LoadFeatures().ok());
  EXPECT_EQ(data.features_crc32(), crc);
  data.PinIdentity(0, crc + 1);
  const Result<FeatureDbView> refused = data.LoadFeatures();
  ASSERT_FALSE(refused.ok());
  EXPECT_EQ(refused.status().code(), StatusCode::kFailedPrecondition);
  EXPECT_NE(std::string(refused.status().message()).find("features_crc32"), std::string::npos)
      << refused.status().message();
  EXPECT_EQ(data.features_crc32(), 0u);
  FileDataSource set(files.set.c_str(), "", &calib);
  set.PinIdentity(0, crc + 1);
  ASSERT_TRUE(set.LoadFeatures().ok());
  EXPECT_EQ(set.features_crc32(), 0u);
}

// `tables = ` one model set (hash tables and the cartons' database as its sections, no
// `features` key) gives the result sets that the separate blobs give, scene for scene.
TEST(FirmwarePrinted, OneModelSetAsTablesGivesTheSamePosesAsTheSeparateBlobs) {
  const Files& files = TestFiles();
  ASSERT_FALSE(files.set_blob.empty());
  static render::SimWorld world;
  ASSERT_TRUE(BuildCartonWorld(files, 2, &world));
  static Pipeline pipeline;
  static texture::TextureRecognizer texture;
  static texture::TextureResult texture_result;
  // Result set of each scene seen, for one configuration of the data.
  auto run = [&](const char* tables, const char* features, std::vector<ResultSet>* by_scene) {
    PlcBus can;
    hal::SimGpio gpio;
    hal::SimCamera camera(&world, hal::SimCameraConfig{});
    FileDataSource data(tables, "", &world.calibration());
    data.SetFeaturesPath(features);
    PipelineRecognition recognition({&pipeline, &texture, &texture_result},
                                    WithClockStandingStill());
    SceneObserver observer(&world);
    const CoreDevices devices =
        SimCoreDevices(can.fw, &gpio, &camera, &recognition, &data, &observer);
    auto core = std::make_unique<FirmwareCore>();
    ASSERT_TRUE(core->Start(CartonCoreConfig(), devices).ok());
    ASSERT_EQ(core->state(), FirmwareState::kReady) << tables;
    EXPECT_EQ(core->loaded_models(), 10u) << tables;
    ResultAssembler assembler(1);
    by_scene->assign(2, ResultSet());
    for (uint8_t i = 0; i < 2; ++i) {
      ASSERT_TRUE(can.plc->Send(TriggerFrame(1, uint8_t(1 + i))).ok());
      ResultSet set;
      ASSERT_TRUE(WaitResultSet(can.plc, &assembler, &set, 12000));
      const int scene = observer.SceneOf(set.sequence);
      ASSERT_TRUE(scene >= 0 && scene < 2);
      (*by_scene)[size_t(scene)] = set;
    }
    core->Stop();
  };
  std::vector<ResultSet> separate, one_set;
  run("builtin", files.features.c_str(), &separate);
  run(files.set.c_str(), "", &one_set);
  int compared = 0, objects = 0;
  for (size_t scene = 0; scene < 2; ++scene) {
    const ResultSet &a = separate[scene], &b = one_set[scene];
    if (a.request_id == 0 || b.request_id == 0) continue;  // scene not seen by both runs
    ++compared;
    ASSERT_EQ(a.object_count, b.object_count) << "scene " << scene;
    objects += a.object_count;
    for (int k = 0; k < a.object_count; ++k) {
      EXPECT_EQ(a.objects[k].model_id, b.objects[k].model_id);
      for (int c = 0; c < 3; ++c)
        EXPECT_EQ(a.objects[k].cam_t_model_mm[c], b.objects[k].cam_t_model_mm[c]);
      for (int c = 0; c < 4; ++c)
        EXPECT_EQ(a.objects[k].cam_q_model[c], b.objects[k].cam_q_model[c]);
    }
  }
  EXPECT_GE(compared, 1);
  EXPECT_GT(objects, 0);
}

// A model set whose cartons' section is damaged is a fault of the tables (the file named by
// `tables`): EMCY 0x6300 with the tables' detail, heartbeat on, ready once the file is repaired.
TEST(FirmwarePrinted, DamagedModelSetIsATablesFaultUntilReplaced) {
  const Files& files = TestFiles();
  ASSERT_FALSE(files.set_blob.empty());
  const std::string configured = files.dir + "/configured_set.bin";
  ASSERT_TRUE(CopyFile(files.damaged_set, configured));
  Rig rig;
  rig.data = std::make_unique<FileDataSource>(configured.c_str(), "", &rig.calib);
  rig.Start();
  rig.ExpectBootDataFault(kDetailTables);
  // The log names the damaged section.
  const std::string why = rig.data->LoadTable().status().message();
  EXPECT_NE(why.find("section 1 (TEXTURE_FEATURES) CRC-32"), std::string::npos) << why;

  ASSERT_TRUE(WriteFile(configured, files.set_blob));
  rig.ClearFault();
  std::optional<CommandAck> ack = rig.WaitAck(0x04);
  ASSERT_TRUE(ack);
  EXPECT_EQ(ack->status, 0);
  EXPECT_TRUE(rig.WaitState(FirmwareState::kReady));
  EXPECT_EQ(rig.core.loaded_models(), 10u);  // six polyhedra and four cartons, from the one file
}

}  // namespace
}  // namespace sh::testing
