#include "tools/eval/rendered_eval.hpp"

#include <cstring>
#include <memory>

#include "hal/sim/world/ray_caster.hpp"
#include "hal/sim/world/renderer.hpp"
#include "tables/model_files.hpp"

namespace sh {

Status LoadRenderModels(const char* dir, const TableView& table, RenderModels* out) {
  SH_RETURN_IF_ERROR(LoadModelFolder(dir, &out->world));
  out->table.clear();
  for (uint32_t i = 0; i < table.model_count(); ++i) out->table.push_back(table.model(i));
  return Status::Ok();
}

ConstGrayView RenderedPair::left_view() const {
  const CameraIntrinsics& c = generated.calib.left;
  return {left.data(), c.width, c.height, c.width};
}

ConstGrayView RenderedPair::right_view() const {
  const CameraIntrinsics& c = generated.calib.right;
  return {right.data(), c.width, c.height, c.width};
}

Status RenderPair(uint64_t seed, const render::ScenarioParams& params, const RenderModels& models,
                  RenderedPair* out) {
  Result<render::GeneratedScene> g = render::GenerateScene(seed, params, models.world.data(),
                                                           static_cast<int>(models.world.size()));
  if (!g.ok()) return g.status();
  out->generated = *g;
  const CameraIntrinsics& l = out->generated.calib.left;
  const CameraIntrinsics& r = out->generated.calib.right;
  out->left.assign(size_t(l.width) * l.height, 0);
  out->right.assign(size_t(r.width) * r.height, 0);
  SH_RETURN_IF_ERROR(render::RenderStereo(
      out->generated.scene, models.world.data(), static_cast<int>(models.world.size()),
      out->generated.calib, GrayView{out->left.data(), l.width, l.height, l.width},
      GrayView{out->right.data(), r.width, r.height, r.width}));
  out->truth.clear();
  for (size_t i = 0; i < out->generated.scene.objects.size(); ++i) {
    const Model& m = models.world[out->generated.scene.objects[i].model_index];
    const int t = FindModelByName(models.table, m.name);
    if (t < 0) continue;  // a model the table does not know is clutter, not a miss
    out->truth.push_back({t, out->generated.left_T_model[i]});
  }
  return Status::Ok();
}

std::vector<RecognizedPose> PosesOf(const PipelineResult& result) {
  std::vector<RecognizedPose> poses;
  for (const RecognizedObject& o : result.objects) poses.push_back({o.model, o.cam_T_model});
  return poses;
}

std::vector<float> VisibleFractions(const render::RenderScene& scene,
                                    const std::vector<Model>& models, const CameraIntrinsics& cam,
                                    const RigidTransform& cam_T_table) {
  const RigidTransform table_T_cam = cam_T_table.Inverse();
  auto full = std::make_unique<render::RayCaster>();
  auto alone = std::make_unique<render::RayCaster>();
  const size_t n = scene.objects.size();
  std::vector<float> fraction(n, 1.0f);
  if (!full->Prepare(scene, models.data(), static_cast<int>(models.size())).ok()) return fraction;
  for (size_t i = 0; i < n; ++i) {
    render::RenderScene one = scene;
    one.objects.clear();
    (void)one.objects.push_back(scene.objects[i]);
    (void)alone->Prepare(one, models.data(), static_cast<int>(models.size()));
    int seen = 0, whole = 0;
    for (int y = 0; y < cam.height; y += 2) {
      for (int x = 0; x < cam.width; x += 2) {
        const Eigen::Vector3f d = table_T_cam.Rotate(
            PixelRay(cam, {static_cast<double>(x), static_cast<double>(y)}).cast<float>());
        if (alone->Cast(table_T_cam.t_mm, d).object != 0) continue;
        ++whole;
        seen += full->Cast(table_T_cam.t_mm, d).object == static_cast<int>(i) ? 1 : 0;
      }
    }
    if (whole > 0) fraction[i] = static_cast<float>(seen) / static_cast<float>(whole);
  }
  return fraction;
}

}  // namespace sh
