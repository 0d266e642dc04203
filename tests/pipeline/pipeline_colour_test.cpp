// A model set that mixes the plain polyhedra (hash tables) and coloured prisms of the same shapes
// (view database): a red cube is a cube to the polyhedral path's corners and edges too. The
// shape path runs first and the colour parts it finds are hidden from the polyhedral path, which
// reports nothing inside them: one object, one report, by the path whose model it is. Also the
// rule itself (CentreInside, Interpenetrate) by its geometry, and no heap in the mixed path (this
// binary counts operator new).
#include <gtest/gtest.h>

#include <atomic>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "hal/sim/world/sim_world.hpp"
#include "recog/geometry/rigid_transform.hpp"
#include "recog/pipeline/pipeline.hpp"
#include "recog/verify/inside_object.hpp"
#include "tables/model_files.hpp"
#include "tables/table_file.hpp"
#include "tests/support/aligned_blob.hpp"
#include "tests/support/counting_allocator.hpp"
#include "tests/support/temp_dir.hpp"
#include "tests/support/test_files.hpp"
#include "tests/support/tool_run.hpp"
#include "tools/tablegen/shape_view_builder.hpp"

namespace sh {
namespace {

Model Box(float x_mm, float y_mm, float z_mm) {
  Model m;
  m.n_corners = 8;
  for (int i = 0; i < 8; ++i) {
    m.corners_mm[i][0] = (i & 1) ? x_mm : 0.0f;
    m.corners_mm[i][1] = (i & 2) ? y_mm : 0.0f;
    m.corners_mm[i][2] = (i & 4) ? z_mm : 0.0f;
  }
  return m;
}

RigidTransform Pose(const Eigen::Vector3f& axis, float angle_rad, const Eigen::Vector3f& t_mm) {
  RigidTransform p;
  p.R = Eigen::AngleAxisf(angle_rad, axis.normalized()).toRotationMatrix();
  p.t_mm = t_mm;
  return p;
}

TEST(CentreInside, AnObjectIsInsideItselfAtAnyPose) {
  const Model cube = Box(40, 40, 40);
  for (int k = 0; k < 20; ++k) {
    const RigidTransform p =
        Pose(Eigen::Vector3f(0.3f * k, 1.0f, -0.5f), 0.31f * k, Eigen::Vector3f(k, -2 * k, 400));
    EXPECT_TRUE(CentreInside(cube, p, {&cube, p})) << k;
  }
}

TEST(CentreInside, FollowsTheOtherObjectsFrameNotTheCamera) {
  const Model cube = Box(40, 40, 40);
  const Model small = Box(10, 10, 10);  // centre (5, 5, 5) in its frame
  const RigidTransform other = Pose(Eigen::Vector3f::UnitZ(), 0.7f, Eigen::Vector3f(50, 20, 400));
  // The small box placed at model points of the cube: inside near its far corner, outside past it.
  RigidTransform at = other;
  at.t_mm = other * Eigen::Vector3f(30, 30, 30);  // centre at (35, 35, 35) of the cube
  EXPECT_TRUE(CentreInside(small, at, {&cube, other}));
  at.t_mm = other * Eigen::Vector3f(36, 30, 30);  // centre at x = 41: outside
  EXPECT_FALSE(CentreInside(small, at, {&cube, other}));
  at.t_mm = other * Eigen::Vector3f(-5, -5, -5);  // centre on the cube's corner: inside
  EXPECT_TRUE(CentreInside(small, at, {&cube, other}));
  // Two cubes side by side on a table touch but do not contain each other's centre.
  RigidTransform beside = other;
  beside.t_mm = other * Eigen::Vector3f(40, 0, 0);
  EXPECT_FALSE(CentreInside(cube, beside, {&cube, other}));
  EXPECT_FALSE(CentreInside(cube, other, {&cube, beside}));
}

TEST(CentreInside, AnyNamesTheFirstContainerAndEmptyModelsContainNothing) {
  const Model cube = Box(40, 40, 40), empty;
  const RigidTransform p = Pose(Eigen::Vector3f::UnitX(), 0.2f, Eigen::Vector3f(0, 0, 300));
  RigidTransform far = p;
  far.t_mm.x() += 500;
  const PosedModel others[3] = {{&cube, far}, {&empty, p}, {&cube, p}};
  EXPECT_EQ(CentreInsideAny(cube, p, others, 3), 2);
  EXPECT_EQ(CentreInsideAny(cube, p, others, 2), -1);
  EXPECT_EQ(CentreInsideAny(empty, p, others, 3), -1);
  EXPECT_FALSE(CentreInside(cube, p, {nullptr, p}));
}

TEST(CentreInside, InterpenetrateHoldsWhenEitherCentreIsInTheOther) {
  const Model cube = Box(40, 40, 40);
  const Model small = Box(10, 10, 10);
  const RigidTransform p = Pose(Eigen::Vector3f::UnitY(), 0.4f, Eigen::Vector3f(10, 0, 450));
  // The small box's centre inside the cube; the cube's centre (20, 20, 20) outside the small box.
  RigidTransform at = p;
  at.t_mm = p * Eigen::Vector3f(2, 2, 2);
  ASSERT_TRUE(CentreInside(small, at, {&cube, p}));
  ASSERT_FALSE(CentreInside(cube, p, {&small, at}));
  EXPECT_TRUE(Interpenetrate({&cube, p}, {&small, at}));
  EXPECT_TRUE(Interpenetrate({&small, at}, {&cube, p}));
  // Side by side: neither holds the other's centre.
  at.t_mm = p * Eigen::Vector3f(45, 0, 0);
  EXPECT_FALSE(Interpenetrate({&cube, p}, {&small, at}));
  EXPECT_FALSE(Interpenetrate({&small, at}, {&cube, p}));
  EXPECT_FALSE(Interpenetrate({nullptr, p}, {&cube, p}));
}

int64_t FakeClock() {
  // Called from the pipeline's worker threads too: one atomic count.
  static std::atomic<int64_t> t{0};
  return t += 1000;  // 1 us per call: the budget is never reached
}

// Coloured copies of three of the reference polyhedra (models/colour, three different colours).
constexpr const char* kParts[] = {"cube", "hexagon", "wedge"};

struct Frames {
  std::vector<uint8_t> y[2];
  std::vector<CbCr8> cbcr[2];
};

class PipelineColour : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new testing::TempDir("pipeline_colour");
    ASSERT_TRUE(dir_->ok());
    std::vector<ShapeModelInput> inputs;
    std::string manifest;
    for (const char* name : kParts) {
      const std::string src = std::string(STEREOHASH_MODELS_DIR) + "/colour/" + name;
      for (const char* ext : {".obj", ".mtl"}) {
        const std::string text = testing::ReadFileText(src + ext);
        ASSERT_FALSE(text.empty()) << src << ext;
        ASSERT_TRUE(
            testing::WriteTestFile(dir_->Sub(std::string(name) + ext), text.data(), text.size()));
      }
      manifest += std::string(name) + "\n";
      Result<Model> m = LoadModelFile(src + ".obj");
      ASSERT_TRUE(m.ok()) << m.status().message();
      ShapeModelInput in;
      in.model = *m;
      ASSERT_TRUE(LoadModelColour(src + ".obj", in.model, in.kd).ok());
      inputs.push_back(in);
    }
    ASSERT_TRUE(testing::WriteTestFile(dir_->Sub("models.txt"), manifest.data(), manifest.size()));
    ShapeViewBuildOptions options;  // fewer components and PCA views: quick under qemu
    options.n_components = 60;
    options.pca_views = 1500;
    Result<std::vector<uint8_t>> blob = BuildShapeViewBlob(inputs, options);
    ASSERT_TRUE(blob.ok()) << blob.status().message();
    blob_ = new testing::AlignedBlob(*blob);
    Result<ShapeViewsView> views = ShapeViewsView::Open(blob_->data, blob_->size);
    ASSERT_TRUE(views.ok()) << views.status().message();
    views_ = new ShapeViewsView(*views);
    Result<TableView> t = OpenDefaultTable();
    ASSERT_TRUE(t.ok()) << t.status().message();
    table_ = new TableView(*t);

    world_ = new render::SimWorld();
    render::SimWorldConfig wc;
    wc.models_dir = STEREOHASH_MODELS_DIR;
    wc.colour_dir = dir_->path().c_str();
    wc.seed = 5;
    wc.scenes = kScenes;
    wc.objects = 4;
    const Status built = world_->Build(wc);
    ASSERT_TRUE(built.ok()) << built.message();
    ASSERT_TRUE(world_->colour());
    const CameraIntrinsics& cam = world_->calibration().left;
    frames_ = new std::vector<Frames>(kScenes);
    const size_t chroma = size_t((cam.width + 1) / 2) * size_t((cam.height + 1) / 2);
    for (int i = 0; i < kScenes; ++i) {
      Frames& f = (*frames_)[size_t(i)];
      hal::Nv12Target target[2];
      for (int k = 0; k < 2; ++k) {
        f.y[k].resize(size_t(cam.width) * size_t(cam.height));
        f.cbcr[k].resize(chroma);
        target[k].y = {f.y[k].data(), cam.width, cam.height, cam.width};
        target[k].cbcr = {f.cbcr[k].data(), (cam.width + 1) / 2, (cam.height + 1) / 2,
                          (cam.width + 1) / 2};
      }
      ASSERT_TRUE(world_->RenderNv12(uint64_t(i), target[0], target[1]).ok());
    }
    pipeline_ = new Pipeline();
    // On the calling thread: the colour path on the pipeline's threads runs under ThreadSanitizer
    // in fw_colour_test, and its refinement on several threads gives what one gives
    // (shape_recognizer_test).
    PipelineConfig config = PipelineConfig::Automatic();
    config.threads = 1;
    const Status s = pipeline_->Init(world_->calibration(), *table_, config, FakeClock, views_);
    ASSERT_TRUE(s.ok()) << s.message();
  }
  static void TearDownTestSuite() {
    delete pipeline_;
    delete frames_;
    delete world_;
    delete table_;
    delete views_;
    delete blob_;
    delete dir_;
  }

  static FrameView View(const Frames& f, int k) {
    const CameraIntrinsics& cam = world_->calibration().left;
    return FrameView::Nv12(
        {f.y[k].data(), cam.width, cam.height, cam.width},
        {f.cbcr[k].data(), (cam.width + 1) / 2, (cam.height + 1) / 2, (cam.width + 1) / 2},
        YcbcrEncoding::kRec601, YcbcrRange::kFull);
  }

  // The pipeline's model id of a world model: a plain polyhedron by its name in the hash tables,
  // a colour part by its name among the view database's models.
  static int IdOf(int world_model) {
    const Model& m = world_->models()[world_model];
    if (!world_->is_coloured(world_model)) return table_->FindModel(m.name);
    for (uint32_t k = 0; k < views_->model_count(); ++k) {
      if (std::string(views_->model(k).name) == m.name) {
        return int(pipeline_->models().shape_offset() + k);
      }
    }
    return -1;
  }

  static constexpr int kScenes = 6;
  static testing::TempDir* dir_;
  static testing::AlignedBlob* blob_;
  static ShapeViewsView* views_;
  static TableView* table_;
  static render::SimWorld* world_;
  static std::vector<Frames>* frames_;
  static Pipeline* pipeline_;
};

testing::TempDir* PipelineColour::dir_ = nullptr;
testing::AlignedBlob* PipelineColour::blob_ = nullptr;
ShapeViewsView* PipelineColour::views_ = nullptr;
TableView* PipelineColour::table_ = nullptr;
render::SimWorld* PipelineColour::world_ = nullptr;
std::vector<Frames>* PipelineColour::frames_ = nullptr;
Pipeline* PipelineColour::pipeline_ = nullptr;

Eigen::Vector3f Centre(const Model& m, const RigidTransform& cam_T_model) {
  Eigen::Vector3f c = Eigen::Vector3f::Zero();
  for (int i = 0; i < m.n_corners; ++i) c += m.corner(i) / float(m.n_corners);
  return cam_T_model * c;
}

// One test, so the view database and the scenes are built once (slow under qemu).
TEST_F(PipelineColour, AColourPartIsReportedOnceByItsOwnPathWithoutTouchingTheHeap) {
  static PipelineResult result;
  const ModelSet& models = pipeline_->models();
  int colour_truth = 0, colour_found = 0, polyhedra_found = 0, polyhedra_truth = 0;
  int duplicates = 0, hidden = 0;
  // A first frame before counting (nothing should allocate then either, but the count is of
  // frames after start-up).
  ASSERT_TRUE(pipeline_->Process(View((*frames_)[0], 0), View((*frames_)[0], 1), 0, &result).ok());
  for (int i = 0; i < kScenes; ++i) {
    const Frames& f = (*frames_)[size_t(i)];
    const uint64_t before = testing::HeapAllocations();
    ASSERT_TRUE(pipeline_->Process(View(f, 0), View(f, 1), 0, &result).ok());
    EXPECT_EQ(testing::HeapAllocations() - before, 0u) << "heap allocations in scene " << i;
    const render::GeneratedScene& g = world_->scene(i);
    for (size_t k = 0; k < g.scene.objects.size(); ++k) {
      const int wm = g.scene.objects[k].model_index;
      const int id = IdOf(wm);
      ASSERT_GE(id, 0) << world_->models()[wm].name;
      const bool colour = models.is_shape(uint32_t(id));
      colour_truth += colour;
      polyhedra_truth += !colour;
      const Eigen::Vector3f truth_mm = Centre(world_->models()[wm], g.left_T_model[k]);
      for (const RecognizedObject& o : result.objects) {
        const Model& m = models.model(o.model);
        const float d_mm = (Centre(m, o.cam_T_model) - truth_mm).norm();
        if (d_mm > 5.0f) continue;
        if (int(o.model) == id) {
          (colour ? colour_found : polyhedra_found) += 1;
        } else if (colour && !models.is_shape(o.model)) {
          ++duplicates;  // a polyhedron where a colour part stands
        }
      }
    }
    hidden += int(result.hidden_colour_parts);
    int colour_reported = 0;
    for (const RecognizedObject& o : result.objects) colour_reported += models.is_shape(o.model);
    EXPECT_EQ(int(result.hidden_colour_parts), colour_reported) << "scene " << i;
  }
  std::printf(
      "%d colour parts, %d found, %d polyhedra reported on them; %d polyhedra, %d found; "
      "%d colour parts hidden\n",
      colour_truth, colour_found, duplicates, polyhedra_truth, polyhedra_found, hidden);
  ASSERT_GE(colour_truth, 4);  // the scenes do mix them
  EXPECT_GE(colour_found * 4, colour_truth * 3);
  EXPECT_EQ(duplicates, 0);
  EXPECT_GE(polyhedra_found * 2, polyhedra_truth);
}

}  // namespace
}  // namespace sh
