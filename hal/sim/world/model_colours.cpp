#include "hal/sim/world/model_colours.hpp"

#include "tables/model_files.hpp"

namespace sh::render {

Status LoadModelColours(const std::string& dir, const std::vector<Model>& models,
                        std::vector<ModelColour>* colours) {
  colours->assign(models.size(), ModelColour{});
  for (size_t i = 0; i < models.size(); ++i) {
    float kd[3];
    const Status s = LoadModelColour(dir + "/" + models[i].name + ".obj", models[i], kd);
    if (s.code() == StatusCode::kNotFound) continue;  // a plain (grey) model
    SH_RETURN_IF_ERROR(s);
    (*colours)[i].coloured = true;
    (*colours)[i].kd = Eigen::Vector3f(kd[0], kd[1], kd[2]);
  }
  return Status::Ok();
}

bool AnyColoured(const std::vector<ModelColour>& colours) {
  for (const ModelColour& c : colours) {
    if (c.coloured) return true;
  }
  return false;
}

void PaintColourParts(const std::vector<ModelColour>& colours, RenderScene* scene) {
  for (SceneObject& o : scene->objects) {
    if (o.model_index >= colours.size() || !colours[o.model_index].coloured) continue;
    o.colour = colours[o.model_index].kd;
    o.albedo = 1.0f;
  }
}

}  // namespace sh::render
