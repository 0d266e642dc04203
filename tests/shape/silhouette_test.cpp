// Silhouettes: scan conversion against the ray tracer's object labels (the same pixels up to
// the boundary), symmetry of the centroid, clipping, and refusals.
#include "recog/shape/silhouette.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <memory>
#include <vector>

#include "hal/sim/world/renderer.hpp"
#include "tables/model_files.hpp"

namespace sh {
namespace {

Model Load(const char* name) {
  Result<Model> m = LoadModelFile(std::string("models/colour/") + name + ".obj");
  EXPECT_TRUE(m.ok()) << m.status().message();
  return m.ok() ? *m : Model{};
}

CameraIntrinsics Camera(double k1) {
  CameraIntrinsics c;
  c.width = 756;
  c.height = 581;
  c.fx = c.fy = 1136.4;
  c.cx = 377.5;
  c.cy = 290.0;
  c.k1 = k1;
  return c;
}

class SilhouetteTest : public ::testing::TestWithParam<const char*> {
 protected:
  std::unique_ptr<SilhouetteScratch> scratch_ = std::make_unique<SilhouetteScratch>();
};

TEST_P(SilhouetteTest, SamePixelsAsTheRayTracersLabelsUpToTheBoundary) {
  const Model model = Load(GetParam());
  ASSERT_GT(model.n_faces, 0);
  const CameraIntrinsics cam = Camera(-0.12);
  // Table 450 mm in front of the camera, tilted; the object 60 mm above it at a skew pose.
  render::RenderScene scene;
  scene.left_T_table.R = Eigen::AngleAxisf(2.3f, Eigen::Vector3f::UnitX()).toRotationMatrix();
  scene.left_T_table.t_mm = {10, 20, 450};
  scene.noise_sigma = 0;
  render::SceneObject object;
  object.model_index = 0;
  object.table_T_model.R =
      Eigen::AngleAxisf(0.9f, Eigen::Vector3f(0.3f, 0.8f, 0.5f).normalized()).toRotationMatrix();
  object.table_T_model.t_mm = {-20, 15, 60};
  ASSERT_TRUE(scene.objects.push_back(object));
  const size_t pixels = static_cast<size_t>(cam.width) * static_cast<size_t>(cam.height);
  std::vector<uint8_t> image(pixels), labels(pixels);
  render::RenderTargets targets;
  targets.image = {image.data(), cam.width, cam.height, cam.width};
  targets.labels = {labels.data(), cam.width, cam.height, cam.width};
  ASSERT_TRUE(render::RenderView(scene, &model, 1, cam, scene.left_T_table, 0, targets).ok());

  const ViewCamera view{cam, RigidTransform::Identity()};
  const PosedModel posed{&model, scene.left_T_table * object.table_T_model};
  SilhouetteMask mask;
  ASSERT_TRUE(RasterizeSilhouette(view, posed, *scratch_, &mask).ok());
  ASSERT_FALSE(mask.empty());
  EXPECT_FALSE(mask.clipped);
  int labelled = 0, differ = 0;
  double lx = 0, ly = 0;
  for (int y = 0; y < cam.height; ++y) {
    for (int x = 0; x < cam.width; ++x) {
      const bool in_label = labels[y * cam.width + x] == 1;
      labelled += in_label;
      if (in_label) lx += x, ly += y;
      differ += in_label != mask.inside(x, y);
    }
  }
  EXPECT_EQ(static_cast<int>(mask.area_px), static_cast<int>(mask.area_px));
  EXPECT_GT(labelled, 1000);
  // Only pixels whose centre lies within a fraction of a pixel of the outline may differ (the
  // projected edges are straight between the distorted corners).
  EXPECT_LT(differ, labelled / 50) << differ << " of " << labelled;
  EXPECT_NEAR(mask.cx, lx / labelled, 0.2);
  EXPECT_NEAR(mask.cy, ly / labelled, 0.2);
}

INSTANTIATE_TEST_SUITE_P(Models, SilhouetteTest,
                         ::testing::Values("cube", "star", "can", "bracket", "wedge"));

TEST(Silhouette, CentredCubeFaceOnHasItsCentroidOnTheAxisAndItsAnalyticArea) {
  const Model cube = Load("cube");
  auto scratch = std::make_unique<SilhouetteScratch>();
  CameraIntrinsics cam = Camera(0);
  cam.cx = 378;  // pixel centre: a symmetric silhouette centres on it
  cam.cy = 290;
  const ViewCamera view{cam, RigidTransform::Identity()};
  // Model z towards the camera: the front face is the model's +z face.
  const PosedModel posed{&cube, {Eigen::Matrix3f::Identity(), {0, 0, 400}}};
  SilhouetteMask mask;
  ASSERT_TRUE(RasterizeSilhouette(view, posed, *scratch, &mask).ok());
  EXPECT_NEAR(mask.cx, 378, 1e-3);
  EXPECT_NEAR(mask.cy, 290, 1e-3);
  // The nearest face (z = half the height nearer) bounds the outline: width * f / depth.
  float xmin = 1e9f, xmax = -1e9f, ymin = 1e9f, ymax = -1e9f, zmin = 1e9f;
  for (int i = 0; i < cube.n_corners; ++i) {
    xmin = std::min(xmin, cube.corner(i).x());
    xmax = std::max(xmax, cube.corner(i).x());
    ymin = std::min(ymin, cube.corner(i).y());
    ymax = std::max(ymax, cube.corner(i).y());
    zmin = std::min(zmin, cube.corner(i).z());
  }
  const double depth = 400 + zmin;
  const double area = (xmax - xmin) * (ymax - ymin) * cam.fx * cam.fy / (depth * depth);
  EXPECT_NEAR(mask.area_px, area, 0.02 * area);
}

// The area and centroid are those of the mask's pixels, summed in doubles, exactly.
TEST(Silhouette, AreaAndCentroidAreThoseOfTheMasksPixels) {
  auto scratch = std::make_unique<SilhouetteScratch>();
  const ViewCamera view{Camera(-0.1), RigidTransform::Identity()};
  int checked = 0;
  for (const char* name : {"bracket", "star", "can"}) {
    const Model model = Load(name);
    for (int k = 0; k < 4; ++k) {
      const Eigen::Matrix3f R =
          Eigen::AngleAxisf(0.7f * k + 0.3f, Eigen::Vector3f(1, 2, 3 - k).normalized())
              .toRotationMatrix();
      // The last pose half out of the right border: a clipped mask.
      const Eigen::Vector3f t(k == 3 ? 140.0f : -40.0f + 25.0f * k, 10.0f * k - 15.0f, 420.0f);
      SilhouetteMask mask;
      ASSERT_TRUE(RasterizeSilhouette(view, {&model, {R, t}}, *scratch, &mask).ok());
      double sx = 0, sy = 0;
      uint32_t area = 0;
      for (int y = 0; y < mask.height; ++y) {
        for (int x = 0; x < mask.width; ++x) {
          if (!mask.mask[static_cast<size_t>(y) * mask.width + x]) continue;
          ++area;
          sx += x;
          sy += y;
        }
      }
      ASSERT_GT(area, 0u) << name << k;
      EXPECT_EQ(mask.area_px, area) << name << k;
      EXPECT_EQ(mask.cx, static_cast<float>(mask.x0 + sx / area)) << name << k;
      EXPECT_EQ(mask.cy, static_cast<float>(mask.y0 + sy / area)) << name << k;
      checked += k == 3 ? mask.clipped : 1;
    }
  }
  EXPECT_EQ(checked, 12);
}

TEST(Silhouette, ClippedOutsideAndBehindTheCamera) {
  const Model cube = Load("cube");
  auto scratch = std::make_unique<SilhouetteScratch>();
  const ViewCamera view{Camera(0), RigidTransform::Identity()};
  SilhouetteMask mask;
  // Half out of the left border.
  ASSERT_TRUE(RasterizeSilhouette(view, {&cube, {Eigen::Matrix3f::Identity(), {-156, 0, 450}}},
                                  *scratch, &mask)
                  .ok());
  EXPECT_TRUE(mask.clipped);
  EXPECT_EQ(mask.x0, 0);
  EXPECT_FALSE(mask.empty());
  // Wholly outside.
  ASSERT_TRUE(RasterizeSilhouette(view, {&cube, {Eigen::Matrix3f::Identity(), {900, 0, 450}}},
                                  *scratch, &mask)
                  .ok());
  EXPECT_TRUE(mask.empty());
  // Behind.
  EXPECT_EQ(
      RasterizeSilhouette(view, {&cube, {Eigen::Matrix3f::Identity(), {0, 0, 5}}}, *scratch, &mask)
          .code(),
      StatusCode::kOutOfRange);
  EXPECT_FALSE(RasterizeSilhouette(view, {nullptr, {}}, *scratch, &mask).ok());
}

}  // namespace
}  // namespace sh
