#include "recog/model/obj_texture.hpp"

#include <gtest/gtest.h>

#include <Eigen/Core>
#include <cmath>
#include <cstring>
#include <fstream>
#include <iterator>
#include <string>

#include "recog/model/obj_model.hpp"
#include "tests/support/test_models.hpp"

namespace sh {
namespace {

struct Parsed {
  Model model;
  ModelTexturing texturing;
};

Result<Parsed> ParseBoth(const std::string& obj, const std::string& mtl = "") {
  Result<Model> model = ParseObjModel(obj.data(), obj.size(), "test");
  if (!model.ok()) return model.status();
  Result<ModelTexturing> tex = ParseObjTexturing(obj.data(), obj.size(), *model);
  if (!tex.ok()) return tex.status();
  if (!mtl.empty()) SH_RETURN_IF_ERROR(ParseMtl(mtl.data(), mtl.size(), &*tex));
  return Parsed{*model, *tex};
}

Eigen::Vector2f Uv(const FaceTextureMap& map, const Eigen::Vector3f& x) {
  float uv[2];
  FaceUv(map, x.data(), uv);
  return {uv[0], uv[1]};
}

// Texture pixels per millimetre along the face's first edge, for an atlas of the given width
// and height.
float TexelsPerMm(const Model& m, int f, const FaceTextureMap& map, int w, int h) {
  const ModelFace& face = m.faces[f];
  const Eigen::Vector3f a = m.corner(face.vertices[0]);
  const Eigen::Vector3f b = m.corner(face.vertices[1]);
  const Eigen::Vector2f d = Uv(map, b) - Uv(map, a);
  return Eigen::Vector2f(d.x() * w, d.y() * h).norm() / (b - a).norm();
}

TEST(ObjTexture, PrintedCartonsMapEveryFaceAtFourTexelsPerMillimetre) {
  // The four cartons of models/textured are exported at 4 texels per millimetre on every face;
  // each face's map must reproduce that along both of its axes.
  const struct {
    const char* stem;
    int w, h;
  } kCartons[] = {
      {"tea", 840, 480}, {"cereal", 1200, 400}, {"pills", 720, 260}, {"tools", 1080, 360}};
  for (const auto& carton : kCartons) {
    const std::string stem = std::string("textured/") + carton.stem;
    const std::string obj = testing::ReadModelText(stem);
    std::string mtl_path = std::string(STEREOHASH_MODELS_DIR) + "/" + stem + ".mtl";
    std::ifstream in(mtl_path);
    const std::string mtl((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    Result<Parsed> p = ParseBoth(obj, mtl);
    ASSERT_TRUE(p.ok()) << carton.stem << ": " << p.status().message();
    const Model& m = p->model;
    const ModelTexturing& t = p->texturing;
    EXPECT_EQ(m.n_faces, 6);
    EXPECT_STREQ(t.mtllib, (std::string(carton.stem) + ".mtl").c_str());
    ASSERT_EQ(t.n_materials, 1);
    EXPECT_STREQ(t.materials[0].map_kd, (std::string(carton.stem) + ".png").c_str());
    for (int f = 0; f < m.n_faces; ++f) {
      const FaceTextureMap& map = t.faces[f];
      EXPECT_EQ(map.material, 0) << carton.stem << " face " << f;
      EXPECT_LT(map.max_fit_error, 1e-5f);
      EXPECT_NEAR(TexelsPerMm(m, f, map, carton.w, carton.h), 4.0f, 0.02f) << carton.stem << f;
      // Second axis: along the face's last edge.
      const ModelFace& face = m.faces[f];
      const Eigen::Vector3f a = m.corner(face.vertices[0]);
      const Eigen::Vector3f c = m.corner(face.vertices[face.n_vertices - 1]);
      const Eigen::Vector2f d = Uv(map, c) - Uv(map, a);
      EXPECT_NEAR(Eigen::Vector2f(d.x() * carton.w, d.y() * carton.h).norm() / (c - a).norm(), 4.0f,
                  0.02f);
      // Every corner maps into the atlas.
      for (int k = 0; k < face.n_vertices; ++k) {
        const Eigen::Vector2f uv = Uv(map, m.corner(face.vertices[k]));
        EXPECT_GE(uv.x(), -1e-5f);
        EXPECT_LE(uv.x(), 1.0f + 1e-5f);
        EXPECT_GE(uv.y(), -1e-5f);
        EXPECT_LE(uv.y(), 1.0f + 1e-5f);
      }
    }
  }
}

// A 2 x 2 x 2 cube; the top face (z = 1) as two triangles with vt, the rest untextured.
constexpr char kCubeHead[] = R"(mtllib box.mtl
v 0 0 0
v 2 0 0
v 2 2 0
v 0 2 0
v 0 0 2
v 2 0 2
v 2 2 2
v 0 2 2
vt 0.1 0.2
vt 0.5 0.2
vt 0.5 0.6
vt 0.1 0.6
f 1 4 3 2
f 1 2 6 5
f 2 3 7 6
f 3 4 8 7
f 4 1 5 8
usemtl print
)";

TEST(ObjTexture, TriangulatedFaceGetsOneMapThroughItsVertices) {
  const std::string obj = std::string(kCubeHead) + "f 5/1 6/2 7/3\nf 5/1 7/3 8/4\n";
  Result<Parsed> p = ParseBoth(obj, "newmtl print\nKd 0.5 0.25 1\nmap_Kd -s 1 1 1 art.png\n");
  ASSERT_TRUE(p.ok()) << p.status().message();
  const Model& m = p->model;
  int textured = 0;
  for (int f = 0; f < m.n_faces; ++f) {
    const FaceTextureMap& map = p->texturing.faces[f];
    if (map.material < 0) continue;
    ++textured;
    EXPECT_NEAR(m.face_normal(f).z(), 1.0f, 1e-6f);
    const Eigen::Vector2f uv5 = Uv(map, {0, 0, 2});
    const Eigen::Vector2f uv7 = Uv(map, {2, 2, 2});
    const Eigen::Vector2f mid = Uv(map, {1, 0.5f, 2});
    EXPECT_NEAR(uv5.x(), 0.1f, 1e-6f);
    EXPECT_NEAR(uv5.y(), 0.2f, 1e-6f);
    EXPECT_NEAR(uv7.x(), 0.5f, 1e-6f);
    EXPECT_NEAR(uv7.y(), 0.6f, 1e-6f);
    EXPECT_NEAR(mid.x(), 0.3f, 1e-6f);
    EXPECT_NEAR(mid.y(), 0.3f, 1e-6f);
  }
  EXPECT_EQ(textured, 1);
  EXPECT_TRUE(p->texturing.textured());
  EXPECT_STREQ(p->texturing.materials[0].map_kd, "art.png");  // options skipped
  EXPECT_FLOAT_EQ(p->texturing.materials[0].kd[1], 0.25f);
}

TEST(ObjTexture, UntexturedModelHasNoTexturedFace) {
  const std::string obj = testing::ReadModelText("cube");
  Result<Parsed> p = ParseBoth(obj);
  ASSERT_TRUE(p.ok()) << p.status().message();
  EXPECT_FALSE(p->texturing.textured());
  EXPECT_STREQ(p->texturing.mtllib, "");
}

void ExpectRefused(const std::string& obj, const char* fragment, const std::string& mtl = "") {
  Result<Parsed> p = ParseBoth(obj, mtl);
  ASSERT_FALSE(p.ok()) << "accepted: " << obj;
  EXPECT_NE(std::strstr(p.status().message(), fragment), nullptr) << p.status().message();
}

TEST(ObjTexture, RefusesBrokenTexturingWithTheReason) {
  const std::string head(kCubeHead);
  ExpectRefused(head + "f 5/1 6/9 7/3 8/4\n", "texture coordinate 9 but 4 are defined");
  ExpectRefused(head + "f 5/1 6/2 7 8/4\n", "some vertices only");
  ExpectRefused(head + "f 5/1 6/x 7/3 8/4\n", "malformed face vertex");
  // A twisted quad: not one affine map.
  ExpectRefused(head + "f 5/1 6/2 7/4 8/3\n", "not one planar (affine) mapping");
  // Half the face with, half without texture coordinates.
  ExpectRefused(head + "f 5/1 6/2 7/3\nf 5 7 8\n", "with and without texture");
  // Two materials on one face.
  ExpectRefused(head + "f 5/1 6/2 7/3\nusemtl other\nf 5/1 7/3 8/4\n", "mixes materials");
  ExpectRefused(head + "vt 0.1\nf 5/1 6/2 7/3 8/4\n", "vt) needs 2 finite numbers");
  ExpectRefused(head + "f 5/1 6/2 7/3 8/4\n", "map_Kd before newmtl", "map_Kd a.png\n");
  ExpectRefused(head + "f 5/1 6/2 7/3 8/4\n", "Kd needs three numbers", "newmtl print\nKd 1 2 0\n");
}

TEST(ObjTexture, NegativeReferencesCountBack) {
  std::string obj(kCubeHead);
  obj += "f -4/-4 -3/-3 -2/-2 -1/-1\n";
  Result<Parsed> p = ParseBoth(obj);
  ASSERT_TRUE(p.ok()) << p.status().message();
  EXPECT_TRUE(p->texturing.textured());
}

}  // namespace
}  // namespace sh
