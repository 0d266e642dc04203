#include "recog/model/obj_model.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <set>
#include <string>
#include <utility>

#include "tests/support/test_models.hpp"

namespace sh {
namespace {

struct Expected {
  const char* stem;
  int corners;
  int edges;
};

// P and L of the model table in the models README.
constexpr Expected kReferenceModels[] = {{"cube", 8, 12},      {"hexagon", 12, 18},
                                         {"wedge", 6, 9},      {"star", 20, 30},
                                         {"pentagon", 10, 15}, {"trapezium", 8, 12}};

// Every edge runs between consecutive corners of the outlines of both its faces.
void ExpectEdgesOnTheirFaces(const Model& m) {
  for (int e = 0; e < m.n_edges; ++e) {
    const ModelEdge& edge = m.edges[e];
    for (int f : {edge.face0, edge.face1}) {
      const ModelFace& face = m.faces[f];
      bool found = false;
      for (int k = 0; k < face.n_vertices; ++k) {
        const int u = face.vertices[k], v = face.vertices[(k + 1) % face.n_vertices];
        found |= (u == edge.a && v == edge.b) || (u == edge.b && v == edge.a);
      }
      EXPECT_TRUE(found) << m.name << " edge " << e << " not on face " << f;
    }
  }
}

// Checks the invariants every parsed model must satisfy: a closed polyhedron (Euler), every
// corner on the plane of every face that lists it, outward normals, edges between two faces
// that both list the edge's corners consecutively. Corners lie on their faces within
// `plane_tolerance_mm`.
void CheckConsistent(const Model& m, float plane_tolerance_mm = 1e-3f) {
  EXPECT_EQ(m.n_corners - m.n_edges + m.n_faces, 2) << m.name;
  Eigen::Vector3f centroid = Eigen::Vector3f::Zero();
  for (int i = 0; i < m.n_corners; ++i) centroid += m.corner(i);
  centroid /= m.n_corners;
  for (int f = 0; f < m.n_faces; ++f) {
    const ModelFace& face = m.faces[f];
    EXPECT_NEAR(m.face_normal(f).norm(), 1.0f, 1e-5f);
    for (int k = 0; k < face.n_vertices; ++k) {
      EXPECT_NEAR(m.face_normal(f).dot(m.corner(face.vertices[k])), face.offset_mm,
                  plane_tolerance_mm);
    }
    // The models are star-shaped about their centroid: outward normals face away from it.
    EXPECT_GT(face.offset_mm - m.face_normal(f).dot(centroid), 0.0f) << m.name << " face " << f;
  }
  std::set<std::pair<int, int>> seen;
  for (int e = 0; e < m.n_edges; ++e) {
    const ModelEdge& edge = m.edges[e];
    EXPECT_TRUE(seen.insert({std::min(edge.a, edge.b), std::max(edge.a, edge.b)}).second);
    EXPECT_NE(edge.face0, edge.face1);
    // Faces meeting at an edge are not coplanar.
    EXPECT_LT(m.face_normal(edge.face0).dot(m.face_normal(edge.face1)), 0.9999f);
  }
  ExpectEdgesOnTheirFaces(m);
}

TEST(ObjModel, ReferenceModelsHaveTheDocumentedCornerAndEdgeCounts) {
  for (const Expected& expected : kReferenceModels) {
    const Result<Model> model = testing::LoadReferenceModel(expected.stem);
    ASSERT_TRUE(model.ok()) << expected.stem << ": " << model.status().message();
    EXPECT_STREQ(model->name, expected.stem);
    EXPECT_EQ(model->n_corners, expected.corners) << expected.stem;
    EXPECT_EQ(model->n_edges, expected.edges) << expected.stem;
    EXPECT_EQ(model->n_faces, expected.edges - expected.corners + 2) << expected.stem;
    EXPECT_EQ(model->n_symmetries, 0);
    CheckConsistent(*model);
  }
}

TEST(ObjModel, StarTopAndBottomAreTenSidedFaces) {
  const Result<Model> star = testing::LoadReferenceModel("star");
  ASSERT_TRUE(star.ok()) << star.status().message();
  int ten_gons = 0;
  for (int f = 0; f < star->n_faces; ++f) ten_gons += star->faces[f].n_vertices == 10;
  EXPECT_EQ(ten_gons, 2);
}

// The cube of models/cube.obj, each square split into two triangles along alternating
// diagonals, with texture/normal index syntax and a midpoint vertex on one edge.
constexpr char kTriangulatedCube[] = R"(# triangulated cube
v -15 -15 -20
v 15 -15 -20
v 15 15 -20
v -15 15 -20
v -15 -15 20
v 15 -15 20
v 15 15 20
v -15 15 20
vn 0 0 1
f 4/1/1 3/1/1 2/1/1
f 4//1 2//1 1//1
f 5 6 7
f 5 7 8
f 1 2 6
f 1 6 5
f 2 3 7
f 2 7 6
f 3 4 8
f 3 8 7
f 4 1 5
f 4 5 8
)";

TEST(ObjModel, TriangulatedCubeMergesIntoTheSameCube) {
  const Result<Model> tri = ParseObjModel(kTriangulatedCube, sizeof(kTriangulatedCube) - 1, "tri");
  ASSERT_TRUE(tri.ok()) << tri.status().message();
  const Result<Model> cube = testing::LoadReferenceModel("cube");
  ASSERT_TRUE(cube.ok());
  EXPECT_EQ(tri->n_corners, cube->n_corners);
  EXPECT_EQ(tri->n_edges, cube->n_edges);
  EXPECT_EQ(tri->n_faces, cube->n_faces);
  for (int f = 0; f < tri->n_faces; ++f) EXPECT_EQ(tri->faces[f].n_vertices, 4);
  CheckConsistent(*tri);
}

// Even-odd test of (x, y) against a face of constant z, as the verifier, the silhouettes and the
// renderers test faces.
bool InsideFaceXy(const Model& m, const ModelFace& face, float x, float y) {
  bool inside = false;
  for (int k = 0, j = face.n_vertices - 1; k < face.n_vertices; j = k++) {
    const Eigen::Vector3f a = m.corner(face.vertices[j]), b = m.corner(face.vertices[k]);
    if ((a.y() > y) != (b.y() > y) && x < a.x() + (b.x() - a.x()) * (y - a.y()) / (b.y() - a.y())) {
      inside = !inside;
    }
  }
  return inside;
}

TEST(ObjModel, AFaceWithAHoleIsOneFaceWhoseOutlineRunsRoundTheHole) {
  const std::string text = testing::PlateWithHoleObj();
  const Result<Model> plate = ParseObjModel(text.data(), text.size(), "plate");
  ASSERT_TRUE(plate.ok()) << plate.status().message();
  EXPECT_EQ(plate->n_corners, 16);
  EXPECT_EQ(plate->n_edges, 24);  // the bridges to the hole are no edges
  EXPECT_EQ(plate->n_faces, 10);
  int holed = 0;
  for (int f = 0; f < plate->n_faces; ++f) {
    const ModelFace& face = plate->faces[f];
    for (int k = 0; k < face.n_vertices; ++k) {
      EXPECT_NEAR(plate->face_normal(f).dot(plate->corner(face.vertices[k])), face.offset_mm,
                  1e-4f);
    }
    if (std::fabs(plate->face_normal(f).z()) < 0.99f) {
      EXPECT_EQ(face.n_vertices, 4);
      continue;
    }
    ++holed;
    EXPECT_EQ(face.n_vertices, 4 + 4 + 2);  // outline, hole, and the bridge's two ends again
    EXPECT_TRUE(InsideFaceXy(*plate, face, 20.0f, 0.5f));
    EXPECT_TRUE(InsideFaceXy(*plate, face, -0.5f, -20.0f));
    EXPECT_FALSE(InsideFaceXy(*plate, face, 0.5f, 0.5f));  // in the hole
    EXPECT_FALSE(InsideFaceXy(*plate, face, 35.0f, 0.5f));
  }
  EXPECT_EQ(holed, 2);
  std::set<std::pair<int, int>> seen;
  for (int e = 0; e < plate->n_edges; ++e) {
    const ModelEdge& edge = plate->edges[e];
    EXPECT_TRUE(seen.insert({std::min(edge.a, edge.b), std::max(edge.a, edge.b)}).second);
    const Eigen::Vector3f d = plate->corner(edge.a) - plate->corner(edge.b);
    EXPECT_NEAR(d.norm(), (std::fabs(d.z()) > 1.0f) ? 10.0f : (d.norm() > 30.0f ? 60.0f : 20.0f),
                1e-4f);
  }
  ExpectEdgesOnTheirFaces(*plate);
}

// 100 x 60 x 10 mm with two 20 x 20 mm square holes, tiled on a grid of quads whose vertices
// along the straight outlines are no corners: a face with two holes on each side.
std::string PlateWithTwoHolesObj() {
  const float xs[] = {-50, -35, -15, 15, 35, 50}, ys[] = {-30, -10, 10, 30};
  auto filled = [](int i, int j) {
    return i >= 0 && i < 5 && j >= 0 && j < 3 && !(j == 1 && (i == 1 || i == 3));
  };
  // OBJ index of grid vertex (i, j), bottom (z -5) or top (z 5).
  auto v = [](int i, int j, bool top) { return 1 + (top ? 24 : 0) + j * 6 + i; };
  std::string obj;
  char line[96];
  for (int top = 0; top < 2; ++top) {
    for (int j = 0; j < 4; ++j) {
      for (int i = 0; i < 6; ++i) {
        std::snprintf(line, sizeof(line), "v %g %g %d\n", xs[i], ys[j], top ? 5 : -5);
        obj += line;
      }
    }
  }
  auto quad = [&](int a, int b, int c, int d) {
    std::snprintf(line, sizeof(line), "f %d %d %d %d\n", a, b, c, d);
    obj += line;
  };
  for (int j = 0; j < 3; ++j) {
    for (int i = 0; i < 5; ++i) {
      if (!filled(i, j)) continue;
      quad(v(i, j, true), v(i + 1, j, true), v(i + 1, j + 1, true), v(i, j + 1, true));
      quad(v(i, j + 1, false), v(i + 1, j + 1, false), v(i + 1, j, false), v(i, j, false));
    }
  }
  for (int j = 0; j < 4; ++j) {  // walls along x, between cells (i, j - 1) and (i, j)
    for (int i = 0; i < 5; ++i) {
      if (filled(i, j) == filled(i, j - 1)) continue;
      if (filled(i, j)) {
        quad(v(i, j, false), v(i + 1, j, false), v(i + 1, j, true), v(i, j, true));
      } else {
        quad(v(i + 1, j, false), v(i, j, false), v(i, j, true), v(i + 1, j, true));
      }
    }
  }
  for (int j = 0; j < 3; ++j) {  // walls along y, between cells (i - 1, j) and (i, j)
    for (int i = 0; i < 6; ++i) {
      if (filled(i - 1, j) == filled(i, j)) continue;
      if (filled(i - 1, j)) {
        quad(v(i, j, false), v(i, j + 1, false), v(i, j + 1, true), v(i, j, true));
      } else {
        quad(v(i, j + 1, false), v(i, j, false), v(i, j, true), v(i, j + 1, true));
      }
    }
  }
  return obj;
}

TEST(ObjModel, AFaceWithTwoHolesBridgesToBoth) {
  const std::string text = PlateWithTwoHolesObj();
  const Result<Model> plate = ParseObjModel(text.data(), text.size(), "plate2");
  ASSERT_TRUE(plate.ok()) << plate.status().message();
  EXPECT_EQ(plate->n_corners, 8 + 2 * 8);
  EXPECT_EQ(plate->n_edges, 12 + 2 * 12);
  EXPECT_EQ(plate->n_faces, 6 + 2 * 4);
  int holed = 0;
  for (int f = 0; f < plate->n_faces; ++f) {
    const ModelFace& face = plate->faces[f];
    if (std::fabs(plate->face_normal(f).z()) < 0.99f) continue;
    ++holed;
    EXPECT_EQ(face.n_vertices, 4 + 2 * (4 + 2));
    for (float x : {-45.0f, 0.5f, 45.0f}) EXPECT_TRUE(InsideFaceXy(*plate, face, x, 0.5f)) << x;
    for (float x : {-25.0f, 25.0f, 55.0f}) EXPECT_FALSE(InsideFaceXy(*plate, face, x, 0.5f)) << x;
  }
  EXPECT_EQ(holed, 2);
  ExpectEdgesOnTheirFaces(*plate);
}

TEST(ObjModel, CarriageReturnLineEndsAreLineEnds) {
  // Old Mac exports end lines with a lone CR, Windows ones with CRLF: the same cube, and line
  // numbers in messages count each line once.
  std::string cr = kTriangulatedCube, crlf;
  for (char& c : cr) c = c == '\n' ? '\r' : c;
  for (char c : std::string(kTriangulatedCube))
    crlf += c == '\n' ? std::string("\r\n") : std::string(1, c);
  for (const std::string& text : {cr, crlf}) {
    const Result<Model> m = ParseObjModel(text.data(), text.size(), "tri");
    ASSERT_TRUE(m.ok()) << m.status().message();
    EXPECT_EQ(m->n_corners, 8);
    EXPECT_EQ(m->n_faces, 6);
  }
  const std::string bad = "v 0 0 0\r\nv 1 0 0\r\nv 0 1 0\r\nf 1 2 9\r\n";
  const Result<Model> m = ParseObjModel(bad.data(), bad.size(), "bad");
  ASSERT_FALSE(m.ok());
  EXPECT_NE(std::string(m.status().message()).find("OBJ line 4"), std::string::npos)
      << m.status().message();
}

// A cube whose bottom face is a fan around an extra centre vertex and whose front face has an
// extra vertex in the middle of its bottom edge: neither extra vertex is a corner.
TEST(ObjModel, VerticesInsideFacesOrOnStraightEdgesAreNotCorners) {
  constexpr char kText[] = R"(
v -15 -15 -20
v 15 -15 -20
v 15 15 -20
v -15 15 -20
v -15 -15 20
v 15 -15 20
v 15 15 20
v -15 15 20
v 0 0 -20
v 0 -15 -20
f 4 3 9
f 3 2 9
f 2 10 9
f 10 1 9
f 1 4 9
f 5 6 7 8
f 1 10 2 6 5
f 2 3 7 6
f 3 4 8 7
f 4 1 5 8
)";
  const Result<Model> m = ParseObjModel(kText, sizeof(kText) - 1, "fan");
  ASSERT_TRUE(m.ok()) << m.status().message();
  EXPECT_EQ(m->n_corners, 8);
  EXPECT_EQ(m->n_edges, 12);
  CheckConsistent(*m);
}

void ExpectError(const char* text, const char* fragment) {
  const Result<Model> m = ParseObjModel(text, std::strlen(text), "bad");
  ASSERT_FALSE(m.ok()) << "accepted: " << text;
  EXPECT_NE(std::string(m.status().message()).find(fragment), std::string::npos)
      << m.status().message();
}

constexpr char kTetra[] = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n";

TEST(ObjModel, RejectsBadInputWithClearMessages) {
  ExpectError("", "no faces");
  ExpectError(kTetra, "no faces");
  ExpectError("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n", "vertex 4");
  ExpectError("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 0\n", "vertex 0");
  ExpectError("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 -9\n", "vertex -9");
  ExpectError("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 x\n", "malformed face");
  ExpectError("v 0 0 nan\n", "non-finite");
  ExpectError("v 0 0 1e999\n", "non-finite");
  ExpectError("v 0 0 inf\n", "non-finite");
  ExpectError("v 0 0\n", "3 coordinates");
  ExpectError("v 0 0 1.2.3\n", "malformed vertex");
  ExpectError("v 0 0 0\nv 1 0 0\nf 1 2\n", "fewer than 3");
  // Open surface: a single triangle.
  ExpectError("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", "one face only");
  // Tetrahedron with one face wound the wrong way, then with all faces wound the wrong way.
  ExpectError((std::string(kTetra) + "f 1 2 3\nf 1 2 4\nf 2 3 4\nf 1 4 3\n").c_str(),
              "inconsistent winding");
  ExpectError((std::string(kTetra) + "f 1 2 3\nf 1 4 2\nf 2 4 3\nf 1 3 4\n").c_str(), "clockwise");
  // Two tetrahedra sharing an edge: three faces meet there.
  ExpectError((std::string(kTetra) + "v 0 0 -1\nv 0 -1 0\nf 1 3 2\nf 1 2 4\nf 2 3 4\nf 3 1 4\n"
                                     "f 1 2 5\nf 1 6 2\nf 2 6 5\nf 1 5 6\n")
                  .c_str(),
              "non-manifold");
  // A non-planar quadrilateral.
  ExpectError("v 0 0 0\nv 1 0 0\nv 1 1 0.5\nv 0 1 0\nf 1 2 3 4\n", "not planar");
}

// The triangulated cube with vertex `moved` (1-based) displaced by `delta_mm`, coordinates
// printed with `decimals` digits after the point.
std::string TriangulatedCube(int moved, const Eigen::Vector3d& delta_mm, int decimals = 6) {
  const double corners[8][3] = {{-15, -15, -20}, {15, -15, -20}, {15, 15, -20}, {-15, 15, -20},
                                {-15, -15, 20},  {15, -15, 20},  {15, 15, 20},  {-15, 15, 20}};
  std::string text;
  char line[128];
  for (int i = 0; i < 8; ++i) {
    Eigen::Vector3d v(corners[i][0], corners[i][1], corners[i][2]);
    if (i + 1 == moved) v += delta_mm;
    std::snprintf(line, sizeof(line), "v %.*f %.*f %.*f\n", decimals, v.x(), decimals, v.y(),
                  decimals, v.z());
    text += line;
  }
  text += "f 4 3 2\nf 4 2 1\nf 5 6 7\nf 5 7 8\nf 1 2 6\nf 1 6 5\nf 2 3 7\nf 2 7 6\n";
  text += "f 3 4 8\nf 3 8 7\nf 4 1 5\nf 4 5 8\n";
  return text;
}

TEST(ObjModel, TrianglesWithinThePlanarityToleranceMergeIntoOneFace) {
  // 4 um off the top plane: coordinates as a CAD export rounds them, far inside 0.01 mm. The
  // triangles of the top face meet at 0.01 degrees; they are one face all the same.
  const std::string text = TriangulatedCube(7, {0.0, 0.0, 0.004}, 3);
  const Result<Model> m = ParseObjModel(text.data(), text.size(), "rounded");
  ASSERT_TRUE(m.ok()) << m.status().message();
  EXPECT_EQ(m->n_corners, 8);
  EXPECT_EQ(m->n_edges, 12);
  EXPECT_EQ(m->n_faces, 6);
  CheckConsistent(*m, static_cast<float>(kObjPlanarityMm));
}

TEST(ObjModel, AFaceBentByLessThanAVisibleEdgeIsRefusedWithTheDistance) {
  // Vertex 7 half a millimetre above the top plane: the top's two triangles bend by 1.3
  // degrees, a face meant to be flat that is not.
  const std::string text = TriangulatedCube(7, {0.0, 0.0, 0.5});
  const Result<Model> m = ParseObjModel(text.data(), text.size(), "bent");
  ASSERT_FALSE(m.ok());
  const std::string message = m.status().message();
  EXPECT_NE(message.find("OBJ lines 11 and 12"), std::string::npos) << message;
  EXPECT_NE(message.find("bend by only"), std::string::npos) << message;
  EXPECT_NE(message.find("vertex"), std::string::npos) << message;
  EXPECT_NE(message.find(" mm off the plane"), std::string::npos) << message;
}

TEST(ObjModel, NonPlanarPolygonRefusalNamesTheVertexAndDistance) {
  ExpectError("v 0 0 0\nv 10 0 0\nv 10 10 2\nv 0 10 0\nf 1 2 3 4\n",
              "OBJ line 5: face is not planar: vertex 1 lies 0.495 mm off its plane "
              "(tolerance 0.01 mm)");
}

TEST(ObjModel, CoordinatesAndSizesOutsideTheSupportedRangeAreRefused) {
  // The cube in micrometres instead of millimetres.
  std::string text = "v -15000000 -15000000 -20000000\n";
  const Result<Model> scaled = ParseObjModel(text.data(), text.size(), "um");
  ASSERT_FALSE(scaled.ok());
  EXPECT_EQ(scaled.status().code(), StatusCode::kOutOfRange);
  EXPECT_NE(std::string(scaled.status().message()).find("-1.5e+07 mm is outside +-10000 mm"),
            std::string::npos)
      << scaled.status().message();
  // 20 times the cube: 1.2 m across, beyond what the tables store.
  text.clear();
  for (const char* v : {"-300 -300 -400", "300 -300 -400", "300 300 -400", "-300 300 -400",
                        "-300 -300 400", "300 -300 400", "300 300 400", "-300 300 400"}) {
    text += std::string("v ") + v + "\n";
  }
  text += "f 4 3 2 1\nf 5 6 7 8\nf 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf 4 1 5 8\n";
  ExpectError(text.c_str(), "the model is 1166 mm across");
  // A speck: 0.03 mm across.
  ExpectError(
      "v 0 0 0\nv 0.02 0 0\nv 0 0.02 0\nv 0 0 0.01\nf 1 3 2\nf 1 2 4\nf 2 3 4\n"
      "f 3 1 4\n",
      "0.03 mm across");
}

TEST(ObjModel, LongVertexIndicesAreQuotedWhole) {
  ExpectError("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 123456789012345\n", "vertex 123456789012345 but 3");
  ExpectError("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 -98765432109\n", "vertex -98765432109 but 3");
}

TEST(ObjModel, RejectsModelsBeyondTheRecordCapacity) {
  // A 63-sided prism has 65 faces (126 corners, 189 edges).
  std::string text;
  const int n = 63;
  for (int z : {0, 10}) {
    for (int i = 0; i < n; ++i) {
      const double a = 2 * M_PI * i / n;
      text += "v " + std::to_string(30 * std::cos(a)) + " " + std::to_string(30 * std::sin(a)) +
              " " + std::to_string(z) + "\n";
    }
  }
  text += "f";
  for (int i = n; i >= 1; --i) text += " " + std::to_string(i);
  text += "\nf";
  for (int i = 1; i <= n; ++i) text += " " + std::to_string(n + i);
  text += "\n";
  for (int i = 0; i < n; ++i) {
    const int a = i + 1, b = (i + 1) % n + 1;
    text += "f " + std::to_string(a) + " " + std::to_string(b) + " " + std::to_string(n + b) + " " +
            std::to_string(n + a) + "\n";
  }
  const Result<Model> m = ParseObjModel(text.data(), text.size(), "prism63");
  ASSERT_FALSE(m.ok());
  EXPECT_EQ(m.status().code(), StatusCode::kResourceExhausted);
  EXPECT_NE(std::string(m.status().message()).find("more than"), std::string::npos);
}

}  // namespace
}  // namespace sh
