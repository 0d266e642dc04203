#include "hal/sim/textured_model_files.hpp"

#include <algorithm>
#include <cmath>

#include "hal/sim/image_files.hpp"
#include "recog/model/obj_model.hpp"
#include "tables/input_file.hpp"
#include "tables/model_files.hpp"

namespace sh {
namespace {

Result<std::string> ReadText(const std::string& path, const char* what) {
  std::string text;
  SH_RETURN_IF_ERROR(ReadInputFile(path, what, size_t(kMaxObjFileBytes), &text));
  return text;
}

std::string Folder(const std::string& path) {
  const size_t slash = path.find_last_of('/');
  return slash == std::string::npos ? std::string(".") : path.substr(0, slash);
}

// Reads the MTL the OBJ at `path` names and the images of its materials.
Status LoadMaterials(const std::string& path, TexturedModel* model) {
  TexturedModel& out = *model;
  const std::string mtl_path = Folder(path) + "/" + out.texturing.mtllib;
  Result<std::string> mtl = ReadText(mtl_path, "material file");
  if (!mtl.ok()) return mtl.status();
  const Status parsed = ParseMtl(mtl->data(), mtl->size(), &out.texturing);
  if (!parsed.ok())
    return Status::Error(parsed.code(), "%s: %s", mtl_path.c_str(), parsed.message());
  for (int m = 0; m < out.texturing.n_materials; ++m) {
    const ObjMaterial& material = out.texturing.materials[m];
    if (material.map_kd[0] == '\0') continue;
    const std::string image_path = Folder(mtl_path) + "/" + material.map_kd;
    GreyImage& image = out.textures[static_cast<size_t>(m)];
    image.pixels.resize(kMaxImagePixels);
    Result<hal::ImageInfo> info = hal::ReadImageFile(image_path.c_str(), hal::PixelFormat::kGray8,
                                                     image.pixels.data(), image.pixels.size());
    if (!info.ok()) {
      return Status::Error(info.status().code(), "%s: %s", image_path.c_str(),
                           info.status().message());
    }
    image.width = info->width;
    image.height = info->height;
    image.pixels.resize(static_cast<size_t>(image.width) * image.height);
    // Kd multiplies the texture: its luma scales the grey image.
    const float luma = 0.299f * material.kd[0] + 0.587f * material.kd[1] + 0.114f * material.kd[2];
    if (luma < 0.999f) {
      for (uint8_t& p : image.pixels) p = static_cast<uint8_t>(std::lround(p * luma));
    }
  }
  return Status::Ok();
}

}  // namespace

Result<TexturedModel> LoadTexturedModelFile(const std::string& path) {
  Result<std::string> obj = ReadText(path, "model file");
  if (!obj.ok()) return obj.status();
  SH_ASSIGN_OR_RETURN(const std::string stem, ModelNameOfFile(path));
  TexturedModel out;
  Result<Model> model = ParseObjModel(obj->data(), obj->size(), stem.c_str());
  if (!model.ok())
    return Status::Error(model.status().code(), "%s: %s", path.c_str(), model.status().message());
  out.model = *model;
  out.model.n_symmetries = 1;  // identity
  const float identity[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
  std::copy(identity, identity + 9, out.model.symmetries[0]);
  Result<ModelTexturing> tex = ParseObjTexturing(obj->data(), obj->size(), out.model);
  if (!tex.ok())
    return Status::Error(tex.status().code(), "%s: %s", path.c_str(), tex.status().message());
  out.texturing = *tex;
  out.textures.resize(static_cast<size_t>(out.texturing.n_materials));
  if (out.texturing.mtllib[0] != '\0') SH_RETURN_IF_ERROR(LoadMaterials(path, &out));
  // A face whose material has no image (a plain Kd colour) carries no print.
  for (int f = 0; f < out.model.n_faces; ++f) {
    int8_t& material = out.texturing.faces[f].material;
    if (material >= 0 && out.textures[static_cast<size_t>(material)].pixels.empty()) {
      material = -1;
    }
  }
  return out;
}

}  // namespace sh
