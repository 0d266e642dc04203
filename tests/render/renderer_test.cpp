#include "hal/sim/world/renderer.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "hal/sim/sim_camera.hpp"
#include "hal/sim/world/scene_generator.hpp"
#include "hal/sim/world/sim_world.hpp"
#include "tables/model_files.hpp"

namespace sh::render {
namespace {

struct Models {
  std::vector<Model> all;
  const Model* models = nullptr;
  int n = 0;
};

const Models& ReferenceModels() {
  static Models* m = [] {
    auto* out = new Models;
    const Status s = LoadModelFolder(STEREOHASH_MODELS_DIR, &out->all);
    EXPECT_TRUE(s.ok()) << s.message();
    out->models = out->all.data();
    out->n = int(out->all.size());
    return out;
  }();
  return *m;
}

struct Images {
  int width = 0, height = 0;
  std::vector<uint8_t> image, labels;
  std::vector<float> depth;
  RenderTargets targets() {
    RenderTargets t;
    t.image = {image.data(), width, height, width};
    t.labels = {labels.data(), width, height, width};
    t.depth_mm = {depth.data(), width, height, width};
    return t;
  }
  explicit Images(const CameraIntrinsics& c)
      : width(c.width),
        height(c.height),
        image(size_t(c.width) * c.height),
        labels(image.size()),
        depth(image.size()) {}
};

GeneratedScene Generate(uint64_t seed, Occlusion occlusion, Background background,
                        float noise = 1.5f) {
  const Models& m = ReferenceModels();
  ScenarioParams p;
  p.n_objects = 5;
  p.occlusion = occlusion;
  p.background = background;
  p.noise_sigma = noise;
  Result<GeneratedScene> g = GenerateScene(seed, p, m.models, m.n);
  EXPECT_TRUE(g.ok()) << g.status().message();
  return *g;
}

TEST(SceneGenerator, ObjectsRestOnTheTableInsideBothImages) {
  const Models& m = ReferenceModels();
  ASSERT_EQ(m.n, 6);
  for (uint64_t seed : {1, 2, 3}) {
    for (Occlusion occ : {Occlusion::kNone, Occlusion::kSome, Occlusion::kSevere}) {
      const GeneratedScene g = Generate(seed, occ, Background::kDark);
      ASSERT_EQ(g.scene.objects.size(), 5u);
      const RigidTransform right_T_table = RightFromTable(g.scene, g.calib);
      for (size_t i = 0; i < g.scene.objects.size(); ++i) {
        const SceneObject& o = g.scene.objects[i];
        const Model& model = m.models[o.model_index];
        // Ground truth is the composition of the table pose and the object pose.
        const RigidTransform expected = g.scene.left_T_table * o.table_T_model;
        EXPECT_LT((expected.R - g.left_T_model[i].R).norm(), 1e-5f);
        EXPECT_LT((expected.t_mm - g.left_T_model[i].t_mm).norm(), 1e-3f);
        float min_z = 1e9f;
        for (int c = 0; c < model.n_corners; ++c) {
          const Eigen::Vector3f p_table = o.table_T_model * model.corner(c);
          min_z = std::min(min_z, p_table.z());
          for (int cam = 0; cam < 2; ++cam) {
            const Eigen::Vector3f p =
                cam == 0 ? g.left_T_model[i] * model.corner(c) : right_T_table * p_table;
            Eigen::Vector2d px;
            ASSERT_TRUE(
                ProjectToPixel(cam == 0 ? g.calib.left : g.calib.right, p.cast<double>(), &px));
            EXPECT_TRUE(px.x() >= 0 && px.y() >= 0 && px.x() < 756 && px.y() < 581);
          }
        }
        EXPECT_NEAR(min_z, 0.0f, 1e-3f) << model.name;  // resting on the table, not sunk
      }
    }
  }
}

TEST(SceneGenerator, RefusesBadParameters) {
  const Models& m = ReferenceModels();
  ScenarioParams p;
  p.camera_distance_mm = 1000;
  EXPECT_EQ(GenerateScene(1, p, m.models, m.n).status().code(), StatusCode::kOutOfRange);
  p = ScenarioParams();
  p.n_objects = 0;
  EXPECT_FALSE(GenerateScene(1, p, m.models, m.n).ok());
  p = ScenarioParams();
  p.n_objects = 16;
  p.camera_distance_mm = 200;
  p.occlusion = Occlusion::kNone;
  const Result<GeneratedScene> crowded = GenerateScene(1, p, m.models, m.n);
  ASSERT_FALSE(crowded.ok());
  EXPECT_NE(std::string(crowded.status().message()).find("could not place"), std::string::npos);
  EXPECT_FALSE(GenerateScene(1, ScenarioParams(), m.models, 0).ok());
}

TEST(SceneGenerator, AFixedTiltGivesEverySceneOneTablePose) {
  const Models& m = ReferenceModels();
  ScenarioParams p;
  Result<GeneratedScene> first = GenerateScene(11, p, m.models, m.n);
  ASSERT_TRUE(first.ok()) << first.status().message();
  EXPECT_GE(first->tilt_deg, 12.0f);
  EXPECT_LE(first->tilt_deg, 22.0f);
  Result<GeneratedScene> drawn = GenerateScene(12, p, m.models, m.n);
  ASSERT_TRUE(drawn.ok());
  // Drawn per scene: another seed, another tilt, another table pose.
  EXPECT_NE(drawn->tilt_deg, first->tilt_deg);
  EXPECT_GT((drawn->scene.left_T_table.R - first->scene.left_T_table.R).norm(), 1e-3f);

  p.tilt_deg = first->tilt_deg;
  Result<GeneratedScene> fixed = GenerateScene(12, p, m.models, m.n);
  ASSERT_TRUE(fixed.ok()) << fixed.status().message();
  EXPECT_EQ(fixed->tilt_deg, first->tilt_deg);
  EXPECT_LT((fixed->scene.left_T_table.t_mm - first->scene.left_T_table.t_mm).norm(), 1e-3f);
  EXPECT_LT((fixed->scene.left_T_table.R - first->scene.left_T_table.R).norm(), 1e-6f);
  // The same seed with its own tilt fixed is the scene it draws.
  p.tilt_deg = drawn->tilt_deg;
  Result<GeneratedScene> same = GenerateScene(12, p, m.models, m.n);
  ASSERT_TRUE(same.ok());
  ASSERT_EQ(same->scene.objects.size(), drawn->scene.objects.size());
  for (size_t i = 0; i < same->scene.objects.size(); ++i) {
    EXPECT_LT((same->left_T_model[i].t_mm - drawn->left_T_model[i].t_mm).norm(), 1e-3f);
  }

  p.tilt_deg = 61.0f;
  EXPECT_EQ(GenerateScene(12, p, m.models, m.n).status().code(), StatusCode::kOutOfRange);
  p.tilt_deg = std::nanf("");
  EXPECT_EQ(GenerateScene(12, p, m.models, m.n).status().code(), StatusCode::kOutOfRange);
}

TEST(SimWorld, EverySceneSharesTheRigAndTheTablePose) {
  SimWorld world;
  SimWorldConfig config;
  config.models_dir = STEREOHASH_MODELS_DIR;
  config.scenes = 4;
  config.seed = 7;
  const Status s = world.Build(config);
  ASSERT_TRUE(s.ok()) << s.message();
  ASSERT_EQ(world.scene_count(), 4);
  for (int i = 0; i < world.scene_count(); ++i) {
    const GeneratedScene& g = world.scene(i);
    EXPECT_EQ(g.tilt_deg, world.scene(0).tilt_deg) << "scene " << i;
    EXPECT_LT((g.scene.left_T_table.t_mm - world.left_T_table().t_mm).norm(), 1e-3f);
    EXPECT_LT((g.scene.left_T_table.R - world.left_T_table().R).norm(), 1e-6f);
    // The objects still differ from scene to scene.
    if (i > 0) {
      EXPECT_GT((g.left_T_model[0].t_mm - world.scene(0).left_T_model[0].t_mm).norm(), 1e-3f);
    }
  }
}

TEST(Renderer, SameSeedGivesIdenticalBytesAndOtherSeedsDiffer) {
  const Models& m = ReferenceModels();
  std::vector<uint8_t> first;
  for (int run = 0; run < 3; ++run) {
    const GeneratedScene g = Generate(run < 2 ? 11 : 12, Occlusion::kSome, Background::kLight);
    Images left(g.calib.left), right(g.calib.right);
    ASSERT_TRUE(
        RenderStereo(g.scene, m.models, m.n, g.calib, left.targets(), right.targets()).ok());
    std::vector<uint8_t> bytes = left.image;
    bytes.insert(bytes.end(), right.image.begin(), right.image.end());
    if (run == 0) {
      first = bytes;
    } else if (run == 1) {
      EXPECT_EQ(bytes, first);
    } else {
      EXPECT_NE(bytes, first);
    }
  }
}

// Max - min of the 5 x 5 neighbourhood of a pixel.
int LocalRange(const Images& im, int x, int y) {
  int lo = 255, hi = 0;
  for (int dy = -2; dy <= 2; ++dy) {
    for (int dx = -2; dx <= 2; ++dx) {
      const int v = im.image[size_t(std::clamp(y + dy, 0, im.height - 1)) * im.width +
                             std::clamp(x + dx, 0, im.width - 1)];
      lo = std::min(lo, v);
      hi = std::max(hi, v);
    }
  }
  return hi - lo;
}

TEST(Renderer, ProjectedCornersSitOnStrongIntensityEdges) {
  const Models& m = ReferenceModels();
  for (Background bg : {Background::kDark, Background::kLight}) {
    const GeneratedScene g = Generate(21, Occlusion::kSome, bg);
    Images left(g.calib.left), right(g.calib.right);
    ASSERT_TRUE(
        RenderStereo(g.scene, m.models, m.n, g.calib, left.targets(), right.targets()).ok());
    int visible = 0, on_edge = 0;
    for (size_t i = 0; i < g.scene.objects.size(); ++i) {
      const Model& model = m.models[g.scene.objects[i].model_index];
      for (int c = 0; c < model.n_corners; ++c) {
        const Eigen::Vector3f p = g.left_T_model[i] * model.corner(c);
        Eigen::Vector2d px;
        ASSERT_TRUE(ProjectToPixel(g.calib.left, p.cast<double>(), &px));
        const int x = static_cast<int>(std::lround(px.x())),
                  y = static_cast<int>(std::lround(px.y()));
        // Visible: a neighbouring pixel shows this object at the corner's depth.
        bool seen = false;
        for (int dy = -1; dy <= 1; ++dy) {
          for (int dx = -1; dx <= 1; ++dx) {
            const size_t k = size_t(y + dy) * left.width + (x + dx);
            seen |= left.labels[k] == i + 1 && std::abs(left.depth[k] - p.z()) < 3.0f;
          }
        }
        if (!seen) continue;
        ++visible;
        on_edge += LocalRange(left, x, y) >= 25;
      }
    }
    EXPECT_GE(visible, 15);
    EXPECT_GE(on_edge, visible * 9 / 10) << "visible " << visible;
  }
}

double Bilinear(const Images& im, double x, double y) {
  const int x0 = static_cast<int>(std::floor(x)), y0 = static_cast<int>(std::floor(y));
  const double fx = x - x0, fy = y - y0;
  auto at = [&](int xx, int yy) { return double(im.image[size_t(yy) * im.width + xx]); };
  return (1 - fy) * ((1 - fx) * at(x0, y0) + fx * at(x0 + 1, y0)) +
         fy * ((1 - fx) * at(x0, y0 + 1) + fx * at(x0 + 1, y0 + 1));
}

// Silhouette edges of a lone cube (one adjacent face towards the camera, one away) cross the
// half-way grey level where ProjectToPixel puts them, to a fraction of a pixel.
TEST(Renderer, SilhouetteEdgesArePositionedToSubPixelAccuracy) {
  const Models& m = ReferenceModels();
  const int cube = FindModelByName(m.all, "cube");
  ASSERT_GE(cube, 0);
  GeneratedScene g = Generate(5, Occlusion::kNone, Background::kDark, 0.0f);
  RenderScene scene = g.scene;
  scene.objects.clear();
  SceneObject o;
  o.model_index = static_cast<uint16_t>(cube);
  o.table_T_model.R = Eigen::AngleAxisf(0.4f, Eigen::Vector3f::UnitZ()).toRotationMatrix();
  o.table_T_model.t_mm = {5, 10, 20};  // resting on its 30 x 30 face
  ASSERT_TRUE(scene.objects.push_back(o));
  Images left(g.calib.left);
  ASSERT_TRUE(
      RenderView(scene, m.models, m.n, g.calib.left, scene.left_T_table, 0, left.targets()).ok());
  const Model& model = m.models[cube];
  const RigidTransform left_T_model = scene.left_T_table * o.table_T_model;
  const Eigen::Vector3f eye_model = left_T_model.Inverse().t_mm;
  int tested = 0, accurate = 0;
  for (int e = 0; e < model.n_edges; ++e) {
    const ModelEdge& edge = model.edges[e];
    auto faces_camera = [&](int f) {
      return model.face_normal(f).dot(eye_model) > model.faces[f].offset_mm;
    };
    if (faces_camera(edge.face0) == faces_camera(edge.face1)) continue;
    Eigen::Vector2d a, b, mid;
    const Eigen::Vector3f pa = left_T_model * model.corner(edge.a);
    const Eigen::Vector3f pb = left_T_model * model.corner(edge.b);
    ASSERT_TRUE(ProjectToPixel(g.calib.left, pa.cast<double>(), &a));
    ASSERT_TRUE(ProjectToPixel(g.calib.left, pb.cast<double>(), &b));
    ASSERT_TRUE(ProjectToPixel(g.calib.left, (0.5f * (pa + pb)).cast<double>(), &mid));
    const Eigen::Vector2d dir = (b - a).normalized();
    const Eigen::Vector2d normal(-dir.y(), dir.x());
    // Profile across the edge at its midpoint; find where it crosses the mid level.
    const double lo = Bilinear(left, mid.x() - 3 * normal.x(), mid.y() - 3 * normal.y());
    const double hi = Bilinear(left, mid.x() + 3 * normal.x(), mid.y() + 3 * normal.y());
    if (std::abs(hi - lo) < 40) continue;  // not enough contrast to measure
    ++tested;
    const double level = 0.5 * (lo + hi);
    double crossing = 1e9;
    for (double s = -3; s < 3; s += 0.01) {
      const double v0 = Bilinear(left, mid.x() + s * normal.x(), mid.y() + s * normal.y()) - level;
      const double v1 =
          Bilinear(left, mid.x() + (s + 0.01) * normal.x(), mid.y() + (s + 0.01) * normal.y()) -
          level;
      if ((v0 <= 0) != (v1 <= 0) && std::abs(s) < std::abs(crossing)) crossing = s;
    }
    accurate += std::abs(crossing) < 0.25;
  }
  EXPECT_GE(tested, 3);
  EXPECT_EQ(accurate, tested);
}

// Occlusion: a pixel shows object i in the full scene only if it shows i when i is alone, and
// where i alone is hidden in the full scene, the object shown instead is nearer to the camera.
TEST(Renderer, OccludedObjectsAreHiddenByNearerOnes) {
  const Models& m = ReferenceModels();
  const GeneratedScene g = Generate(31, Occlusion::kSevere, Background::kDark);
  Images full(g.calib.left);
  ASSERT_TRUE(
      RenderView(g.scene, m.models, m.n, g.calib.left, g.scene.left_T_table, 0, full.targets())
          .ok());
  int occluded = 0;
  for (size_t i = 0; i < g.scene.objects.size(); ++i) {
    RenderScene alone = g.scene;
    alone.objects.clear();
    ASSERT_TRUE(alone.objects.push_back(g.scene.objects[i]));
    Images single(g.calib.left);
    ASSERT_TRUE(
        RenderView(alone, m.models, m.n, g.calib.left, alone.left_T_table, 0, single.targets())
            .ok());
    for (size_t k = 0; k < full.labels.size(); ++k) {
      if (full.labels[k] == i + 1) {
        ASSERT_EQ(single.labels[k], 1) << "pixel " << k;
      }
      if (single.labels[k] == 1 && full.labels[k] != i + 1) {
        ASSERT_NE(full.labels[k], kTableLabel);
        ASSERT_LT(full.depth[k], single.depth[k]);
        ++occluded;
      }
    }
  }
  EXPECT_GT(occluded, 100);
}

// A world with colour parts: the simulator's camera delivers NV12 frames whose Y plane is the
// grey view (zero-copy) and whose colour at each part's projected centre is that part's hue; the
// truth's models are the colour parts after the plain ones.
TEST(SimWorld, ColourPartsComeAsNv12FramesInTheirColour) {
  SimWorld world;
  SimWorldConfig config;
  config.models_dir = STEREOHASH_MODELS_DIR;
  config.colour_dir = STEREOHASH_MODELS_DIR "/colour";
  config.scenes = 2;
  config.objects = 5;
  config.seed = 3;
  const Status s = world.Build(config);
  ASSERT_TRUE(s.ok()) << s.message();
  ASSERT_TRUE(world.colour());
  EXPECT_FALSE(world.is_coloured(0));  // models/ first: the grey cube
  EXPECT_TRUE(world.is_coloured(world.model_count() - 1));
  hal::SimCamera camera(&world, hal::SimCameraConfig{});
  ASSERT_TRUE(camera.Start().ok());
  EXPECT_EQ(camera.format(), FrameFormat::kNv12);
  hal::StereoFrame frame;
  ASSERT_TRUE(camera.Capture(&frame, 100).ok());
  ASSERT_EQ(frame.left_frame.format, FrameFormat::kNv12);
  EXPECT_EQ(frame.left.data, frame.left_frame.luma.data);  // the grey path reads Y in place
  ASSERT_TRUE(CheckFrame(frame.left_frame).ok());
  const GeneratedScene& g = world.scene(world.SceneOfFrame(frame.left_sequence));
  int coloured = 0, hue_right = 0;
  for (size_t i = 0; i < g.scene.objects.size(); ++i) {
    const int m = g.scene.objects[i].model_index;
    if (!world.is_coloured(m)) continue;
    ++coloured;
    // The corner centroid of these convex-ish prisms lies inside them: its pixel shows the part
    // (unless hidden; the scenes keep most parts apart).
    const Model& model = world.models()[m];
    Eigen::Vector3f centroid = Eigen::Vector3f::Zero();
    for (int c = 0; c < model.n_corners; ++c) centroid += model.corner(c) / float(model.n_corners);
    Eigen::Vector2d px;
    ASSERT_TRUE(ProjectToPixel(g.calib.left, (g.left_T_model[i] * centroid).cast<double>(), &px));
    const Rgb8 p = FramePixel(frame.left_frame, int(std::lround(px.x())), int(std::lround(px.y())));
    const Eigen::Vector3f kd = g.scene.objects[i].colour;
    // The strongest channel of the Kd is the strongest of the pixel.
    int kd_max = 0, px_max = 0;
    const int v[3] = {p.r, p.g, p.b};
    for (int k = 1; k < 3; ++k) {
      if (kd[k] > kd[kd_max]) kd_max = k;
      if (v[k] > v[px_max]) px_max = k;
    }
    hue_right += kd_max == px_max ? 1 : 0;
  }
  EXPECT_GE(coloured, 1);
  EXPECT_GE(hue_right, coloured - 1);
  ASSERT_TRUE(camera.Stop().ok());
  // A colour folder holding a model without a Kd is refused by name.
  SimWorld bad;
  config.colour_dir = STEREOHASH_MODELS_DIR;
  const Status refused = bad.Build(config);
  EXPECT_EQ(refused.code(), StatusCode::kInvalidArgument);
  EXPECT_NE(std::string(refused.message()).find("Kd"), std::string::npos) << refused.message();
}

// Colour: an object of diffuse colour Kd shows that colour's hue in the RGB image, the table
// and the grey objects stay neutral, and the grey image is the colour's BT.601 luma; a scene
// without colours renders its grey image byte for byte as before (the luma of equal channels).
TEST(Renderer, ColourObjectsShowTheirKdAndTheGreyImageIsItsLuma) {
  const Models& m = ReferenceModels();
  const GeneratedScene grey = Generate(41, Occlusion::kNone, Background::kDark, 0.0f);
  GeneratedScene coloured = grey;
  ASSERT_GE(coloured.scene.objects.size(), 2u);
  coloured.scene.objects[0].colour = Eigen::Vector3f(0.8f, 0.12f, 0.1f);  // red, as the can's
  const CameraIntrinsics& cam = grey.calib.left;
  Images plain(cam), with_colour(cam);
  std::vector<Rgb8> rgb(size_t(cam.width) * cam.height), plain_rgb(rgb.size());
  RenderTargets t = with_colour.targets();
  t.rgb = {rgb.data(), cam.width, cam.height, cam.width};
  ASSERT_TRUE(
      RenderView(coloured.scene, m.models, m.n, cam, coloured.scene.left_T_table, 0, t).ok());
  RenderTargets tp = plain.targets();
  tp.rgb = {plain_rgb.data(), cam.width, cam.height, cam.width};
  ASSERT_TRUE(RenderView(grey.scene, m.models, m.n, cam, grey.scene.left_T_table, 0, tp).ok());
  // Without noise the channels of a grey scene agree and equal the grey image everywhere.
  for (size_t k = 0; k < rgb.size(); ++k) {
    ASSERT_EQ(plain_rgb[k].r, plain.image[k]);
    ASSERT_EQ(plain_rgb[k].g, plain.image[k]);
    ASSERT_EQ(plain_rgb[k].b, plain.image[k]);
  }
  int red = 0, inside = 0, neutral = 0, others = 0;
  for (size_t k = 0; k < rgb.size(); ++k) {
    const Rgb8 p = rgb[k];
    const float luma = 0.299f * p.r + 0.587f * p.g + 0.114f * p.b;
    ASSERT_LE(std::fabs(luma - float(with_colour.image[k])), 1.0f) << "pixel " << k;
    if (with_colour.labels[k] == 1) {
      ++inside;
      red += (p.r > 2 * p.g + 10 && p.r > 2 * p.b + 10) ? 1 : 0;
    } else if (with_colour.labels[k] > 1) {
      ++others;
      neutral += (p.r == p.g && p.g == p.b) ? 1 : 0;
    }
  }
  EXPECT_GT(inside, 200);
  EXPECT_GT(red, inside * 9 / 10);  // edge pixels mix with the table
  // Other objects stay grey, but for the coloured object's reflections of the lights they never
  // receive: the renderer has no interreflection, so all of them.
  EXPECT_EQ(neutral, others);
  // Only the RGB image is asked for: the same colours without a grey image.
  std::vector<Rgb8> alone(rgb.size());
  RenderTargets only_rgb;
  only_rgb.rgb = {alone.data(), cam.width, cam.height, cam.width};
  ASSERT_TRUE(
      RenderView(coloured.scene, m.models, m.n, cam, coloured.scene.left_T_table, 0, only_rgb)
          .ok());
  for (size_t k = 0; k < rgb.size(); ++k) ASSERT_EQ(alone[k].r, rgb[k].r);
  RenderTargets nothing;
  EXPECT_EQ(RenderView(grey.scene, m.models, m.n, cam, grey.scene.left_T_table, 0, nothing).code(),
            StatusCode::kInvalidArgument);
}

TEST(Renderer, RefusesMismatchedTargetsAndBadModels) {
  const Models& m = ReferenceModels();
  const GeneratedScene g = Generate(1, Occlusion::kSome, Background::kDark);
  std::vector<uint8_t> small(size_t{100} * 100);
  const GrayView view{small.data(), 100, 100, 100};
  const Status wrong_size = RenderStereo(g.scene, m.models, m.n, g.calib, view, view);
  EXPECT_EQ(wrong_size.code(), StatusCode::kInvalidArgument);
  EXPECT_NE(std::string(wrong_size.message()).find("100 x 100"), std::string::npos);
  std::vector<uint8_t> l(size_t{756} * 581), r(size_t{756} * 581);
  const Status missing_models =
      RenderStereo(g.scene, m.models, 2, g.calib, GrayView{l.data(), 756, 581, 756},
                   GrayView{r.data(), 756, 581, 756});
  bool uses_high_index = false;
  for (const SceneObject& o : g.scene.objects) uses_high_index |= o.model_index >= 2;
  if (uses_high_index) {
    EXPECT_EQ(missing_models.code(), StatusCode::kInvalidArgument);
  }
  RenderScene bad = g.scene;
  bad.supersampling = 0;
  EXPECT_EQ(RenderStereo(bad, m.models, m.n, g.calib, GrayView{l.data(), 756, 581, 756},
                         GrayView{r.data(), 756, 581, 756})
                .code(),
            StatusCode::kOutOfRange);
}

}  // namespace
}  // namespace sh::render
