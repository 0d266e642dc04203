// The L bracket (legs 50 and 45 mm) half a turn about its profile's bisector has nearly the same
// silhouette: at poses all over the viewing sphere, with coarse views (20 degrees) and noise so
// that refinement starts far from the truth, the shape path with the near-symmetry check
// (ShapeConfig::near_symmetries) reports fewer brackets turned and finds more, against the same
// scenes without it.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cstdio>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "recog/shape/shape_recognizer.hpp"
#include "recog/shape/view_database.hpp"
#include "tables/model_files.hpp"
#include "tables/shape_view_builder.hpp"
#include "tests/shape/flat_scene.hpp"

namespace sh {
namespace {

struct Counts {
  int found = 0, turned = 0, other = 0;
};

TEST(ShapeFlip, TheBracketIsFoundTheRightWayRound) {
  const std::string path = "models/colour/bracket.obj";
  Result<Model> m = LoadModelFile(path);
  ASSERT_TRUE(m.ok()) << m.status().message();
  ShapeModelInput in;
  in.model = *m;
  ASSERT_TRUE(LoadModelColour(path, in.model, in.kd).ok());
  ShapeViewBuildOptions options;  // quick: fewer components and PCA views
  options.n_components = 60;
  options.pca_views = 1500;
  options.view_spacing_deg = 20.0f;  // coarse views: refinement starts further from the truth
  Result<std::vector<uint8_t>> blob = BuildShapeViewBlob({in}, options);
  ASSERT_TRUE(blob.ok()) << blob.status().message();
  Result<ShapeViewsView> views = ShapeViewsView::Open(blob->data(), blob->size());
  ASSERT_TRUE(views.ok()) << views.status().message();
  const StereoCalibration calib = testing::ThesisRig();

  std::mt19937 rng(17);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  constexpr int kScenes = 24;
  std::vector<testing::FlatImage> left(kScenes), right(kScenes);
  std::vector<RigidTransform> truth(kScenes);
  for (int i = 0; i < kScenes; ++i) {
    const Eigen::Quaternionf q(u(rng), u(rng), u(rng), u(rng));
    testing::FlatPart p;
    p.posed.model = &views->model(0);
    p.posed.cam_T_model.R = q.normalized().toRotationMatrix();
    p.posed.cam_T_model.t_mm = Eigen::Vector3f(40 * u(rng), 30 * u(rng), 450 + 30 * u(rng));
    for (int k = 0; k < 3; ++k) p.kd[k] = views->shape_model(0).kd[k];
    truth[size_t(i)] = p.posed.cam_T_model;
    testing::RenderFlatPair(calib, {p}, 40, 6.0f, &left[size_t(i)], &right[size_t(i)]);
  }
  Counts counts[2];  // without, with the check
  for (int with = 0; with < 2; ++with) {
    ShapeConfig config;
    config.near_symmetries = with != 0;
    auto recognizer = std::make_unique<ShapeRecognizer>();
    ASSERT_TRUE(recognizer->Init(calib, *views, config, 0).ok());
    for (int i = 0; i < kScenes; ++i) {
      Vector<RecognizedObject, kMaxObjects> found;
      ShapeStats stats;
      ASSERT_TRUE(
          recognizer->Process(left[size_t(i)].frame(), right[size_t(i)].frame(), found, &stats)
              .ok());
      for (const RecognizedObject& o : found) {
        const float angle = RotationAngleDeg(o.cam_T_model.R.transpose() * truth[size_t(i)].R);
        const float d_mm = (o.cam_T_model.t_mm - truth[size_t(i)].t_mm).norm();
        if (angle < 2.0f && d_mm < 2.0f) {
          ++counts[with].found;
        } else if (angle > 160.0f) {
          ++counts[with].turned;
        } else {
          ++counts[with].other;
        }
      }
    }
    std::printf("%s the near-symmetry check: %d of %d brackets found, %d turned, %d elsewhere\n",
                with ? "with" : "without", counts[with].found, kScenes, counts[with].turned,
                counts[with].other);
  }
  // Measured (seed 17, 24 poses, views every 20 degrees, noise 6): without the check 12 found,
  // 3 turned, 3 elsewhere; with it 14 found, 1 turned, 3 elsewhere.
  EXPECT_GT(counts[0].turned, 0);  // the scenes do show the ambiguity
  EXPECT_LT(counts[1].turned, counts[0].turned);
  EXPECT_GT(counts[1].found, counts[0].found);
  EXPECT_LE(counts[1].other, counts[0].other);
}

}  // namespace
}  // namespace sh
