#include "hal/sim/world/printed_surface.hpp"

#include <algorithm>
#include <cmath>

namespace sh::render {

float PrintedSurface::Reflectance(int face, const Eigen::Vector3f& x_model) const {
  if (texturing == nullptr || face < 0 || face >= kMaxModelFaces) return 1.0f;
  const FaceTextureMap& map = texturing->faces[face];
  if (map.material < 0) return 1.0f;
  const ConstGrayView& img = images[map.material];
  if (img.empty()) return 1.0f;
  float uv[2];
  FaceUv(map, x_model.data(), uv);
  // Texture coordinates to pixels: pixel centres at integers, row 0 at v = 1.
  const float x = std::clamp(uv[0] * img.width - 0.5f, 0.0f, img.width - 1.0f);
  const float y = std::clamp((1.0f - uv[1]) * img.height - 0.5f, 0.0f, img.height - 1.0f);
  const int x0 = std::min(static_cast<int>(x), img.width - 1);
  const int y0 = std::min(static_cast<int>(y), img.height - 1);
  const int x1 = std::min(x0 + 1, img.width - 1);
  const int y1 = std::min(y0 + 1, img.height - 1);
  const float fx = x - x0, fy = y - y0;
  const float top = img.at(x0, y0) + fx * (img.at(x1, y0) - img.at(x0, y0));
  const float bottom = img.at(x0, y1) + fx * (img.at(x1, y1) - img.at(x0, y1));
  return (top + fy * (bottom - top)) / 255.0f;
}

PrintedSurface PrintOf(const TexturedModel& model) {
  PrintedSurface print;
  print.texturing = &model.texturing;
  for (size_t m = 0; m < model.textures.size() && m < size_t(kMaxObjMaterials); ++m) {
    print.images[m] = model.textures[m].view();
  }
  return print;
}

}  // namespace sh::render
