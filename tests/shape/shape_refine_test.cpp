// Edge refinement in both images: from a pose a few millimetres and degrees off, the projected
// silhouette and crease edges pull the model onto the part, to a fraction of a millimetre.
#include "recog/shape/shape_refine.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <memory>

#include "recog/shape/segmentation.hpp"
#include "tables/model_files.hpp"
#include "tests/shape/flat_scene.hpp"
#include "tests/shape/symmetric_angle.hpp"
#include "tools/tablegen/model_symmetry.hpp"

namespace sh {
namespace {

struct ColouredPart {
  Model model;
  float kd[3];
};

ColouredPart LoadColouredPart(const char* name) {
  ColouredPart p;
  const std::string path = std::string("models/colour/") + name + ".obj";
  Result<Model> m = LoadModelFile(path);
  EXPECT_TRUE(m.ok()) << m.status().message();
  if (m.ok()) p.model = *m;
  StoreSymmetries(p.model, FindSymmetries(p.model));
  EXPECT_TRUE(LoadModelColour(path, p.model, p.kd).ok());
  return p;
}

using testing::SymmetricAngleDeg;

// One part at `truth` rendered flat by the thesis rig, segmented: the images refinement reads.
struct Scene {
  StereoCalibration calib = testing::ThesisRig();
  testing::FlatImage left, right;
  std::unique_ptr<ColourSegmentation[]> seg = std::make_unique<ColourSegmentation[]>(2);
  ShapeImages images;
  uint8_t colour = 0;
};

void Render(const ColouredPart& part, const RigidTransform& truth, Scene* scene) {
  testing::RenderFlatPair(scene->calib,
                          {{{&part.model, truth}, {part.kd[0], part.kd[1], part.kd[2]}}}, 35, 2.0f,
                          &scene->left, &scene->right);
  ColourClassSet set;
  ASSERT_TRUE(DeriveColourClasses(&part.kd, 1, &set, &scene->colour).ok());
  ColourClassifier classifier;
  ASSERT_TRUE(classifier.Init(set).ok());
  ASSERT_TRUE(scene->seg[0].Segment(scene->left.frame(), classifier, SegmentConfig{}).ok());
  ASSERT_TRUE(scene->seg[1].Segment(scene->right.frame(), classifier, SegmentConfig{}).ok());
  for (int cam = 0; cam < 2; ++cam) {
    scene->images.rgb[cam] = scene->seg[cam].rgb();
    scene->images.classes[cam] = scene->seg[cam].classes();
  }
}

RigidTransform Truth() {
  RigidTransform truth;
  truth.R =
      Eigen::AngleAxisf(2.1f, Eigen::Vector3f(0.4f, -0.7f, 0.3f).normalized()).toRotationMatrix();
  truth.t_mm = {-15, 10, 460};
  return truth;
}

class ShapeRefineTest : public ::testing::TestWithParam<const char*> {};

TEST_P(ShapeRefineTest, ConvergesFromAFewMillimetresAndDegreesOff) {
  const ColouredPart part = LoadColouredPart(GetParam());
  const RigidTransform truth = Truth();
  Scene scene;
  Render(part, truth, &scene);
  const StereoCalibration& calib = scene.calib;
  const ShapeImages& images = scene.images;
  const uint8_t colour = scene.colour;

  PosedModel object{&part.model, truth};
  object.cam_T_model.R =
      Eigen::AngleAxisf(0.07f, Eigen::Vector3f(0.2f, 0.9f, -0.4f).normalized()).toRotationMatrix() *
      truth.R;
  object.cam_T_model.t_mm += Eigen::Vector3f(2.5f, -2.0f, 3.0f);
  auto refiner = std::make_unique<ShapeRefiner>();
  ShapeRefineResult result;
  const Status s =
      refiner->Refine(calib, images, colour, &object, nullptr, 0, ShapeRefineConfig{}, &result);
  ASSERT_TRUE(s.ok()) << s.message();
  EXPECT_LT((object.cam_T_model.t_mm - truth.t_mm).norm(), 0.15f);
  if (part.model.n_symmetries == 96) {
    // The can's turn about its axis shows in no edge: only the axis is measured.
    const Eigen::Vector3f axis = object.cam_T_model.R.col(2), true_axis = truth.R.col(2);
    EXPECT_LT(std::acos(std::min(1.0f, std::fabs(axis.dot(true_axis)))) * 57.2958f, 0.3f);
  } else {
    EXPECT_LT(SymmetricAngleDeg(part.model, object.cam_T_model.R, truth.R), 0.3f);
  }
  for (int cam = 0; cam < 2; ++cam) {
    EXPECT_GT(result.fit[cam].samples, 40);
    EXPECT_GT(result.fit[cam].score(), 0.75f) << cam;  // flat shading hides some creases
  }
}

INSTANTIATE_TEST_SUITE_P(Models, ShapeRefineTest,
                         ::testing::Values("cube", "can", "bracket", "star", "wedge"));

// With min_start_share, a start beside the part (its edges beyond the search) is given up after
// the first pass, and a start near it is refined as without.
TEST(ShapeRefine, GivesUpAStartThatFindsFewEdges) {
  const ColouredPart part = LoadColouredPart("wedge");
  const RigidTransform truth = Truth();
  Scene scene;
  Render(part, truth, &scene);
  ShapeRefineConfig config;
  config.min_start_share = 0.25f;
  auto refiner = std::make_unique<ShapeRefiner>();
  ShapeRefineResult result;
  PosedModel beside{&part.model, truth};
  beside.cam_T_model.t_mm += Eigen::Vector3f(60.0f, 0.0f, 0.0f);
  EXPECT_EQ(
      refiner->Refine(scene.calib, scene.images, scene.colour, &beside, nullptr, 0, config, &result)
          .code(),
      StatusCode::kNotFound);
  config.min_start_share = 0.0f;
  const Status without = refiner->Refine(scene.calib, scene.images, scene.colour, &beside, nullptr,
                                         0, config, &result);
  EXPECT_NE(without.code(), StatusCode::kNotFound) << without.message();

  PosedModel near{&part.model, truth};
  near.cam_T_model.t_mm += Eigen::Vector3f(2.5f, -2.0f, 3.0f);
  config.min_start_share = 0.25f;
  const Status s =
      refiner->Refine(scene.calib, scene.images, scene.colour, &near, nullptr, 0, config, &result);
  ASSERT_TRUE(s.ok()) << s.message();
  EXPECT_LT((near.cam_T_model.t_mm - truth.t_mm).norm(), 0.15f);
}

TEST(ShapeRefine, RefusesBadSettingsAndMismatchedImages) {
  ShapeRefineConfig c;
  c.search_end_px = c.search_start_px + 1;
  EXPECT_FALSE(CheckShapeRefineConfig(c).ok());
  c = ShapeRefineConfig{};
  c.iterations = 0;
  EXPECT_FALSE(CheckShapeRefineConfig(c).ok());
  const ColouredPart part = LoadColouredPart("cube");
  ShapeImages images;  // empty frames
  PosedModel object{&part.model, {Eigen::Matrix3f::Identity(), {0, 0, 400}}};
  ShapeRefineResult r;
  auto refiner = std::make_unique<ShapeRefiner>();
  EXPECT_EQ(
      refiner->Refine(testing::ThesisRig(), images, 1, &object, nullptr, 0, ShapeRefineConfig{}, &r)
          .code(),
      StatusCode::kInvalidArgument);
}

}  // namespace
}  // namespace sh
