// Texture mapping of a Wavefront OBJ model: the `vt` coordinates, the `f v/vt` references,
// `usemtl` and `mtllib`, and from the MTL file each material's `map_Kd` image, as CAD and
// packaging tools export printed boxes.
//
// ParseObjModel merges coplanar polygons into the faces of a Model; ParseObjTexturing reads the
// same OBJ text again and gives every Model face the affine map from model millimetres to
// texture coordinates that its polygons' `vt` define. A face is textured when all its polygons
// carry `vt` references with one material; the map must be affine over the face (one planar
// projection of the artwork, as a box net is), else the model is refused with the face named.
#pragma once

#include <cstddef>
#include <cstdint>

#include "recog/base/status.hpp"
#include "recog/model/model.hpp"

namespace sh {

inline constexpr int kMaxObjTexCoords = 1024;
inline constexpr int kMaxObjMaterials = 8;
inline constexpr int kMaxObjFileNameLength = 127;
inline constexpr int kMaxObjMaterialNameLength = 63;

struct ObjMaterial {
  char name[kMaxObjMaterialNameLength + 1] = {};
  char map_kd[kMaxObjFileNameLength + 1] =
      {};                            // diffuse texture file, relative to the MTL; "" if none
  float kd[3] = {1.0f, 1.0f, 1.0f};  // diffuse colour (the texture is multiplied by it)
};

struct FaceTextureMap {
  int8_t material = -1;  // index into ModelTexturing::materials; -1: untextured face
  // (u, v) = uv_from_model * (x, y, z, 1) for model points (millimetres) on the face; row-major
  // 2 x 4. OBJ convention: u to the right, v upwards in the image, both on [0, 1].
  float uv_from_model[8] = {};
  float max_fit_error = 0.0f;  // largest deviation of the face's `vt` from the map (uv units)
};

struct ModelTexturing {
  char mtllib[kMaxObjFileNameLength + 1] = {};  // "" if the OBJ names no MTL file
  int n_materials = 0;
  ObjMaterial materials[kMaxObjMaterials];
  FaceTextureMap faces[kMaxModelFaces];  // by Model face index

  bool textured() const {
    for (const FaceTextureMap& f : faces) {
      if (f.material >= 0) return true;
    }
    return false;
  }
};

// Reads the texture statements of an OBJ whose geometry `model` was parsed from (ParseObjModel
// of the same text). Material names from `usemtl` are recorded without their MTL data; read the
// MTL with ParseMtl. Fails with a message naming the line or face for malformed statements,
// references to undefined `vt`, a face with mixed materials or with and without `vt`, and a
// non-affine mapping.
Result<ModelTexturing> ParseObjTexturing(const char* text, size_t len, const Model& model);

// Reads an MTL file's `newmtl`, `Kd` and `map_Kd` statements into the materials that
// ParseObjTexturing recorded (materials the MTL does not define keep no texture; the MTL's other
// materials are ignored). `map_Kd` options (-s, -o, ...) are skipped: the file is the last token.
Status ParseMtl(const char* text, size_t len, ModelTexturing* texturing);

// Texture coordinates of a model point under a face's map.
inline void FaceUv(const FaceTextureMap& map, const float x_mm[3], float uv[2]) {
  for (int r = 0; r < 2; ++r) {
    const float* m = map.uv_from_model + ptrdiff_t{4} * r;
    uv[r] = m[0] * x_mm[0] + m[1] * x_mm[1] + m[2] * x_mm[2] + m[3];
  }
}

}  // namespace sh
