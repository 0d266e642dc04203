// Deterministic stereo renderer of a RenderScene, through the calibrated cameras' intrinsics
// and lens distortion: every sample casts the ray PixelRay() gives for its (distorted) pixel
// position, so features in the images sit exactly where ProjectToPixel() puts the 3-D points.
//
// Colour: objects reflect their diffuse colour (SceneObject::colour, the MTL Kd) per channel,
// highlights and the table are neutral; the grey image is the colour's BT.601 luma (exactly the
// radiance where the three channels agree, so grey scenes render as before).
//
// Shading: Lambert plus Blinn-Phong highlights from two point lights with cast shadows, an
// ambient term, and on the light table a faint mirror image of the objects. Anti-aliasing: rays
// through all pixel corners; pixels whose four corners see the same surface, shadow and
// reflection get the corners' mean, the others supersampling x supersampling stratified samples
// (box filter), which keeps edges sharp and positioned to a small fraction of a pixel. Gaussian
// sensor noise comes from a hash of (seed, camera, pixel), so the output bytes depend only on
// the inputs.
#pragma once

#include <cstdint>

#include "hal/sim/world/render_scene.hpp"
#include "recog/base/status.hpp"
#include "recog/camera/camera_model.hpp"
#include "recog/image/image.hpp"
#include "recog/model/model.hpp"

namespace sh::render {

// Label value of pixels that show the table (object i shows as i + 1).
inline constexpr uint8_t kTableLabel = 0;

struct RenderTargets {
  GrayView image;             // grey (BT.601 luma of the colour); width and height of the camera
  ImageView<Rgb8> rgb;        // colour (linear R'G'B' like the grey); image, rgb or both required
  GrayView labels;            // optional (empty view = skip): object at the pixel centre
  ImageView<float> depth_mm;  // optional: camera-frame z of the surface at the pixel centre
};

// Renders one camera whose pose is cam_T_table. `camera_index` selects the noise stream.
Status RenderView(const RenderScene& scene, const Model* models, int n_models,
                  const CameraIntrinsics& camera, const RigidTransform& cam_T_table,
                  int camera_index, const RenderTargets& targets);

// Renders the left camera at scene.left_T_table and the right camera at
// calib.right_R_left / right_t_left_mm from it.
Status RenderStereo(const RenderScene& scene, const Model* models, int n_models,
                    const StereoCalibration& calib, GrayView left, GrayView right);
Status RenderStereo(const RenderScene& scene, const Model* models, int n_models,
                    const StereoCalibration& calib, const RenderTargets& left,
                    const RenderTargets& right);

// Pose of the right camera relative to the table.
RigidTransform RightFromTable(const RenderScene& scene, const StereoCalibration& calib);

}  // namespace sh::render
