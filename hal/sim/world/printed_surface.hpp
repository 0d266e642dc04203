// The artwork of a printed model as the renderer sees it: each printed face's map from model
// millimetres to texture coordinates (recog/model/obj_texture.hpp) and the grey texture images,
// sampled bilinearly. Non-owning: the images and the texturing outlive the scene.
#pragma once

#include <Eigen/Core>

#include "recog/image/image.hpp"
#include "recog/model/obj_texture.hpp"
#include "recog/model/textured_model.hpp"

namespace sh::render {

struct PrintedSurface {
  const ModelTexturing* texturing = nullptr;
  ConstGrayView images[kMaxObjMaterials] = {};  // per material; empty = no image

  // Reflectance factor on [0, 1] of the print at model point x on model face `face`: the
  // texture's grey value (bilinear, coordinates clamped to the image); 1 where the face is not
  // printed.
  float Reflectance(int face, const Eigen::Vector3f& x_model) const;
};

// The print of a loaded printed model (its texturing and images, which must outlive it).
PrintedSurface PrintOf(const TexturedModel& model);

}  // namespace sh::render
