// Random but reproducible test scenes: reference objects resting on the table in stable poses,
// seen by a converging stereo pair modelled on the thesis camera (756 x 581 px, 12.5 mm lens,
// 11 um pixels => fx ~ 1136 px) with mild barrel distortion.
#pragma once

#include <cstdint>

#include "hal/sim/world/render_scene.hpp"
#include "recog/base/status.hpp"
#include "recog/camera/camera_model.hpp"
#include "recog/model/model.hpp"

namespace sh::render {

enum class Occlusion : uint8_t {
  kNone,    // objects apart: no object overlaps another in either image
  kSome,    // objects closer: at least one pair overlaps in the left image
  kSevere,  // objects clustered, nearly touching: at least two overlapping pairs
};

// The working volume an integrator would set over this table (table frame: z up from the
// table top, mm): the scenes scatter objects over at most a 60 cm square and no reference
// object rests higher than 70 mm; 3 mm below the top keeps bottom edges whose triangulation
// errs downwards and drops the mirror images of the light table.
inline constexpr float kTableVolumeMinMm[3] = {-350.0f, -350.0f, -3.0f};
inline constexpr float kTableVolumeMaxMm[3] = {350.0f, 350.0f, 150.0f};

struct ScenarioParams {
  int n_objects = 4;  // 1 .. kMaxRenderObjects
  Background background = Background::kDark;
  Occlusion occlusion = Occlusion::kSome;
  float camera_distance_mm = 400.0f;  // rig centre to the fixation point on the table, 200..600
  float spread_mm = 400.0f;           // side of the square the objects are scattered over
  float baseline_mm = 120.0f;
  float noise_sigma = 1.5f;  // grey levels
  // The rig's tilt from the vertical, 0..60 degrees. Negative: drawn for each scene from 12..22
  // degrees. A fixed camera over a conveyor sees every scene from one tilt, so one table pose.
  float tilt_deg = -1.0f;
  // Another camera than the thesis's for both eyes (size, focal length, principal point,
  // distortion); the right one then differs from it as real ones do (focal length -0.4 %,
  // principal point shifted by a few pixels, distortion -5 %). Off: the thesis pair.
  bool custom_camera = false;
  CameraIntrinsics camera;
};

// Cameras other than the thesis's, for scenes that test that nothing is fitted to one lens:
// "thesis" (the default pair), "wide" (1024 x 768, f 760 px, strong barrel distortion,
// off-centre), "tele" (640 x 480, f 1500 px, mild pincushion), "hd" (1280 x 1024, f 1700 px,
// moderate barrel, tangential terms). False for an unknown name.
bool NamedCamera(const char* name, ScenarioParams* params);

// NOLINTNEXTLINE(bugprone-reserved-identifier): clang-tidy 14 names the implicit array copy's index
struct GeneratedScene {
  RenderScene scene;
  StereoCalibration calib;
  // Ground truth: model -> left camera (OpenCV axes, mm), one per scene.objects entry.
  RigidTransform left_T_model[kMaxRenderObjects];
  float tilt_deg = 0.0f;  // the rig's tilt from the vertical this scene was rendered with
};

// Fails with a clear Status if the parameters are out of range or the objects cannot be placed
// (too many objects for the view at that distance).
Result<GeneratedScene> GenerateScene(uint64_t seed, const ScenarioParams& params,
                                     const Model* models, int n_models);

// Stable resting faces of a model: faces whose plane supports the whole model and that contain
// the projection of its centroid. Returns the number written to faces[].
int StableFaces(const Model& model, int* faces);

}  // namespace sh::render
