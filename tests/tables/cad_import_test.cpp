// CAD exports -> models (tools/tablegen/cad_import): the reference models exported by assimp's
// writers as binary and ASCII STL, binary and ASCII PLY, triangulated OBJ and 3MF become the same
// models as their OBJ; units scale; curved surfaces become smooth edges that hashing leaves out;
// malformed files are refused by name.
#include "tools/tablegen/cad_import.hpp"

#include <Eigen/Core>

#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <array>
#include <assimp/Exporter.hpp>
#include <assimp/Importer.hpp>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <string>
#include <utility>
#include <vector>

#include "recog/model/model_features.hpp"
#include "tables/model_files.hpp"
#include "tests/support/temp_dir.hpp"
#include "tests/support/test_models.hpp"
#include "tools/tablegen/table_builder.hpp"

namespace sh {
namespace {

using testing::PrismTriangles;
using testing::TempDir;
using testing::WriteAsciiStl;

const char* const kReference[] = {"cube", "hexagon", "wedge", "star", "pentagon", "trapezium"};

// `obj` triangulated by assimp and written by its exporter `format_id` ("stlb", "ply", ...).
void Export(const std::string& obj, const char* format_id, const std::string& out) {
  Assimp::Importer importer;
  const aiScene* scene = importer.ReadFile(obj, aiProcess_Triangulate);
  ASSERT_NE(scene, nullptr) << importer.GetErrorString();
  Assimp::Exporter exporter;
  ASSERT_EQ(exporter.Export(scene, format_id, out), aiReturn_SUCCESS)
      << format_id << ": " << exporter.GetErrorString();
}

bool Near(const float a[3], const float b[3], double tol) {
  return std::abs(a[0] - b[0]) <= tol && std::abs(a[1] - b[1]) <= tol &&
         std::abs(a[2] - b[2]) <= tol;
}

int FindCorner(const Model& m, const float p[3]) {
  for (int i = 0; i < m.n_corners; ++i) {
    if (Near(m.corners_mm[i], p, 1e-3)) return i;
  }
  return -1;
}

// The same corners, edges (between the same corners) and face planes, in any order.
void ExpectSameModel(const Model& want, const Model& got, const std::string& what) {
  ASSERT_EQ(got.n_corners, want.n_corners) << what;
  ASSERT_EQ(got.n_edges, want.n_edges) << what;
  ASSERT_EQ(got.n_faces, want.n_faces) << what;
  EXPECT_STREQ(got.name, want.name) << what;
  int corner_of[kMaxModelCorners];
  for (int i = 0; i < want.n_corners; ++i) {
    corner_of[i] = FindCorner(got, want.corners_mm[i]);
    ASSERT_GE(corner_of[i], 0) << what << ": corner " << i << " missing";
  }
  for (int e = 0; e < want.n_edges; ++e) {
    const int a = corner_of[want.edges[e].a], b = corner_of[want.edges[e].b];
    bool found = false;
    for (int g = 0; g < got.n_edges && !found; ++g) {
      found = (got.edges[g].a == a && got.edges[g].b == b) ||
              (got.edges[g].a == b && got.edges[g].b == a);
    }
    EXPECT_TRUE(found) << what << ": edge " << e << " missing";
  }
  for (int f = 0; f < want.n_faces; ++f) {
    bool found = false;
    for (int g = 0; g < got.n_faces && !found; ++g) {
      found = Near(got.faces[g].normal, want.faces[f].normal, 1e-5) &&
              std::abs(got.faces[g].offset_mm - want.faces[f].offset_mm) <= 1e-3 &&
              got.faces[g].n_vertices == want.faces[f].n_vertices;
    }
    EXPECT_TRUE(found) << what << ": face " << f << " missing";
  }
}

struct ExportCase {
  const char* format_id;  // assimp's exporter
  const char* extension;
  bool through_import;  // an OBJ export: read as a CAD export
};

class ReferenceExports : public ::testing::TestWithParam<ExportCase> {};

TEST_P(ReferenceExports, AreTheSameModelsAsTheirObj) {
  const ExportCase& c = GetParam();
  TempDir dir("cad");
  CadImportOptions options;
  options.obj_through_import = c.through_import;
  for (const char* name : kReference) {
    const std::string obj = std::string("models/") + name + ".obj";
    const std::string out = dir.Sub(std::string(name) + c.extension);
    Export(obj, c.format_id, out);
    const Result<Model> want = LoadModelFile(obj);
    ASSERT_TRUE(want.ok()) << want.status().message();
    const Result<Model> got = ImportModelFile(out, options);
    ASSERT_TRUE(got.ok()) << out << ": " << got.status().message();
    ExpectSameModel(*want, *got, out);
  }
}

INSTANTIATE_TEST_SUITE_P(
    Formats, ReferenceExports,
    ::testing::Values(ExportCase{"stlb", ".stl", false}, ExportCase{"stl", ".stl", false},
                      ExportCase{"plyb", ".ply", false}, ExportCase{"ply", ".ply", false},
                      ExportCase{"obj", ".obj", true}, ExportCase{"3mf", ".3mf", false}),
    [](const auto& info) { return std::string(info.param.format_id); });

TEST(CadImport, AFolderOfExportsBuildsTheTablesOfItsObjs) {
  TempDir dir("cad");
  const std::string d = dir.Mkdir("models");
  std::vector<std::string> names;
  for (const char* name : kReference) {
    Export(std::string("models/") + name + ".obj", "stlb", d + "/" + name + ".stl");
    names.push_back(name);
  }
  std::vector<Model> want, got;
  ASSERT_TRUE(LoadModels("models", names, &want).ok());
  const Status loaded = LoadModels(d, names, &got, [](const std::string& path) {
    return ImportModelFile(path, CadImportOptions{});
  });
  ASSERT_TRUE(loaded.ok()) << loaded.message();
  TableBuildReport want_report, got_report;
  ASSERT_TRUE(BuildTableBlob(want, TableBuildOptions{}, &want_report).ok());
  ASSERT_TRUE(BuildTableBlob(got, TableBuildOptions{}, &got_report).ok());
  EXPECT_EQ(got_report.bases, want_report.bases);
  EXPECT_EQ(got_report.point_entries, want_report.point_entries);
  EXPECT_EQ(got_report.line_entries, want_report.line_entries);
  for (size_t m = 0; m < want.size(); ++m) {
    EXPECT_EQ(got[m].n_symmetries, want[m].n_symmetries) << want[m].name;
  }
}

TEST(CadImport, FolderListingsTakeEveryFormatAndRefuseAModelInTwo) {
  TempDir dir("cad");
  const std::string d = dir.Mkdir("models");
  Export("models/cube.obj", "stlb", d + "/cube.STL");
  Export("models/wedge.obj", "ply", d + "/wedge.ply");
  std::vector<std::string> names;
  ASSERT_TRUE(ModelFolderNames(d, &names).ok());
  EXPECT_EQ(names, (std::vector<std::string>{"cube", "wedge"}));
  std::vector<Model> models;
  // The board's reader names the host command rather than reading STL as OBJ text.
  Status s = LoadModels(d, names, &models);
  EXPECT_NE(std::string(s.message()).find("read on a host by `stereohash tables build`"),
            std::string::npos)
      << s.message();
  Export("models/cube.obj", "obj", d + "/cube.obj");
  s = LoadModels(d, names, &models,
                 [](const std::string& path) { return ImportModelFile(path, {}); });
  EXPECT_NE(std::string(s.message()).find("model 'cube' has more than one file"), std::string::npos)
      << s.message();
}

TEST(CadImport, UnitsScaleToMillimetresAndAMissingUnitIsNamed) {
  TempDir dir("cad");
  std::vector<std::array<double, 9>> prism = PrismTriangles(6, 0.02, 0.03);  // metres
  WriteAsciiStl(dir.Sub("hex.stl"), prism);
  Result<Model> m = ImportCadModel(dir.Sub("hex.stl"), {});
  ASSERT_FALSE(m.ok());
  EXPECT_NE(std::string(m.status().message()).find("read in mm: give its unit with --units"),
            std::string::npos)
      << m.status().message();
  CadImportOptions metres;
  ASSERT_TRUE(ParseLengthUnit("m", &metres.mm_per_unit));
  metres.unit = "m";
  m = ImportCadModel(dir.Sub("hex.stl"), metres);
  ASSERT_TRUE(m.ok()) << m.status().message();
  EXPECT_EQ(m->n_corners, 12);
  EXPECT_EQ(m->n_faces, 8);
  EXPECT_NEAR(m->corners_mm[0][0] * m->corners_mm[0][0] + m->corners_mm[0][1] * m->corners_mm[0][1],
              400.0, 1e-3);
  double in = 0;
  EXPECT_TRUE(ParseLengthUnit("in", &in));
  EXPECT_EQ(in, 25.4);
  EXPECT_FALSE(ParseLengthUnit("ft", &in));
}

// A can of 32 facets that bend by 11.25 degrees: under the default sharp angle a curved side
// of 32 facets joined by smooth edges, with nothing for hashing (every corner lies on a smooth
// edge); under --sharp-deg 10 a 32-sided prism whose every corner and edge is hashed.
TEST(CadImport, ACurvedSurfaceIsSmoothAndASharperBoundTakesItAsFacets) {
  TempDir dir("cad");
  WriteAsciiStl(dir.Sub("can.stl"), PrismTriangles(32, 20, 30));
  Result<Model> m = ImportCadModel(dir.Sub("can.stl"), {});
  ASSERT_TRUE(m.ok()) << m.status().message();
  EXPECT_EQ(m->n_corners, 64);
  EXPECT_EQ(m->n_edges, 96);
  EXPECT_EQ(m->n_faces, 34);
  ModelFeatures features = FeaturesOf(*m);
  EXPECT_EQ(features.n_smooth_edges, 32);
  EXPECT_EQ(features.n_corners(), 0);
  EXPECT_EQ(features.n_lines(), 0);
  for (int e = 0; e < m->n_edges; ++e) {
    const ModelEdge& edge = m->edges[e];
    // Smooth exactly where two side facets meet; the rims join a facet to a cap.
    const bool between_facets = FaceIsCurved(*m, edge.face0) && FaceIsCurved(*m, edge.face1) &&
                                std::abs(m->corners_mm[edge.a][2] - m->corners_mm[edge.b][2]) > 1;
    EXPECT_EQ(edge.smooth != 0, between_facets) << "edge " << e;
  }

  CadImportOptions facets;
  facets.sharp_deg = 10;
  m = ImportCadModel(dir.Sub("can.stl"), facets);
  ASSERT_TRUE(m.ok()) << m.status().message();
  EXPECT_EQ(m->n_faces, 34);
  features = FeaturesOf(*m);
  EXPECT_EQ(features.n_smooth_edges, 0);
  EXPECT_EQ(features.n_corners(), 64);
  EXPECT_EQ(features.n_lines(), 96);
}

// A square plate with a round bore: n facets round the bore between a top and a bottom face
// each with the bore as a hole, side x side x thickness mm, z 0 .. thickness.
std::vector<std::array<double, 9>> BoredPlate(int n, double side, double thickness,
                                              double bore_radius) {
  std::vector<std::array<double, 9>> t;
  const double half = 0.5 * side;
  auto bore = [&](int i, double z) {
    const double a = 2 * M_PI * i / n;
    return std::array<double, 3>{bore_radius * std::cos(a), bore_radius * std::sin(a), z};
  };
  auto rim = [&](int i, double z) {  // the plate's outline at the bore point's angle
    const double a = 2 * M_PI * i / n;
    const double c = std::cos(a), s = std::sin(a), k = half / std::max(std::abs(c), std::abs(s));
    return std::array<double, 3>{k * c, k * s, z};
  };
  auto quad = [&](std::array<double, 3> p, std::array<double, 3> q, std::array<double, 3> r,
                  std::array<double, 3> u) {  // p q r u counter-clockwise from outside
    t.push_back({p[0], p[1], p[2], q[0], q[1], q[2], r[0], r[1], r[2]});
    t.push_back({p[0], p[1], p[2], r[0], r[1], r[2], u[0], u[1], u[2]});
  };
  const double z1 = thickness;
  for (int i = 0; i < n; ++i) {
    const int j = (i + 1) % n;
    quad(bore(i, z1), rim(i, z1), rim(j, z1), bore(j, z1));  // top
    quad(bore(j, 0), rim(j, 0), rim(i, 0), bore(i, 0));      // bottom
    quad(bore(i, 0), bore(i, z1), bore(j, z1), bore(j, 0));  // the bore's wall faces its axis
    quad(rim(i, 0), rim(j, 0), rim(j, z1), rim(i, z1));      // the plate's sides
  }
  return t;
}

// The plate without its bore, as the same kind of export.
std::vector<std::array<double, 9>> PlainPlate(double side, double thickness) {
  std::vector<std::array<double, 9>> t = PrismTriangles(4, side / std::sqrt(2.0), thickness);
  for (auto& tri :
       t) {  // PrismTriangles' square has its corners on the axes: turn it by 45 degrees
    for (size_t k = 0; k < 9; k += 3) {
      const double x = tri[k], y = tri[k + 1];
      tri[k] = (x - y) / std::sqrt(2.0);
      tri[k + 1] = (x + y) / std::sqrt(2.0);
    }
  }
  return t;
}

// A 60 x 60 x 10 mm plate with a bore of 32 facets: the bore's wall is a curved surface, its
// rims two holes of 32 corners, and hashing takes from it exactly what it takes from the plain
// plate (the same bases and entries), so the stereo path looks for the plate's own corners and
// edges; the bore is left to the verifier.
TEST(CadImport, ABoredPlateHashesAsThePlainPlate) {
  TempDir dir("cad");
  WriteAsciiStl(dir.Sub("bored.stl"), BoredPlate(32, 60, 10, 12));
  WriteAsciiStl(dir.Sub("plain.stl"), PlainPlate(60, 10));
  CadImportOptions centred;
  centred.origin = ModelOrigin::kCentroid;
  const Result<Model> bored = ImportCadModel(dir.Sub("bored.stl"), centred);
  ASSERT_TRUE(bored.ok()) << bored.status().message();
  const Result<Model> plain = ImportCadModel(dir.Sub("plain.stl"), centred);
  ASSERT_TRUE(plain.ok()) << plain.status().message();
  EXPECT_EQ(bored->n_corners, 8 + 64);
  EXPECT_EQ(bored->n_edges, 12 + 64 + 32);
  EXPECT_EQ(bored->n_faces, 6 + 32);
  const ModelFeatures features = FeaturesOf(*bored);
  EXPECT_EQ(features.n_smooth_edges, 32);
  EXPECT_EQ(features.n_corners(), 8);
  EXPECT_EQ(features.n_lines(), 12);
  for (int i = 0; i < bored->n_corners; ++i) {  // the hashed corners are the plate's
    const Eigen::Vector3f p = bored->corner(i);
    EXPECT_EQ(features.corner(i), std::abs(std::abs(p.x()) - 30) < 1e-3f) << "corner " << i;
  }

  TableBuildReport with_bore, without;
  const Result<std::vector<uint8_t>> a = BuildTableBlob({*bored}, TableBuildOptions{}, &with_bore);
  ASSERT_TRUE(a.ok()) << a.status().message();
  const Result<std::vector<uint8_t>> b = BuildTableBlob({*plain}, TableBuildOptions{}, &without);
  ASSERT_TRUE(b.ok()) << b.status().message();
  EXPECT_GT(without.bases, 0u);
  EXPECT_EQ(with_bore.bases, without.bases);
  EXPECT_EQ(with_bore.point_entries, without.point_entries);
  EXPECT_EQ(with_bore.line_entries, without.line_entries);
}

// A plate with a square hole through it, exported as binary STL and as PLY (triangles
// everywhere): the same model as its OBJ, with one face with a hole on each side.
TEST(CadImport, APlateWithAHoleIsTheSameModelAsItsObj) {
  TempDir dir("cad");
  {
    std::ofstream obj(dir.Sub("plate.obj"));
    obj << testing::PlateWithHoleObj();
  }
  const Result<Model> want = LoadModelFile(dir.Sub("plate.obj"));
  ASSERT_TRUE(want.ok()) << want.status().message();
  ASSERT_EQ(want->n_faces, 10);
  for (const auto& [format_id, extension] : {std::pair{"stlb", "stl"}, {"ply", "ply"}}) {
    ASSERT_EQ(mkdir(dir.Sub(format_id).c_str(), 0755), 0);
    const std::string path = dir.Sub(std::string(format_id) + "/plate." + extension);
    Export(dir.Sub("plate.obj"), format_id, path);
    const Result<Model> got = ImportCadModel(path, {});
    ASSERT_TRUE(got.ok()) << format_id << ": " << got.status().message();
    ExpectSameModel(*want, *got, format_id);
  }
}

TEST(CadImport, TheCentroidOriginIsReportedAndMovesThePart) {
  TempDir dir("cad");
  std::vector<std::array<double, 9>> prism = PrismTriangles(4, 20, 30);  // z from 0 to 30
  for (auto& t : prism) {
    for (size_t k = 0; k < 9; k += 3) t[k] += 50;  // and off the z axis
  }
  WriteAsciiStl(dir.Sub("block.stl"), prism);
  CadImportReport report;
  Result<Model> in_file = ImportCadModel(dir.Sub("block.stl"), {}, &report);
  ASSERT_TRUE(in_file.ok()) << in_file.status().message();
  EXPECT_TRUE(report.origin_in_file_mm.isZero());
  EXPECT_NEAR((report.centroid_in_file_mm - Eigen::Vector3d(50, 0, 15)).norm(), 0, 1e-9);
  CadImportOptions centroid;
  centroid.origin = ModelOrigin::kCentroid;
  Result<Model> centred = ImportCadModel(dir.Sub("block.stl"), centroid, &report);
  ASSERT_TRUE(centred.ok()) << centred.status().message();
  EXPECT_NEAR((report.origin_in_file_mm - Eigen::Vector3d(50, 0, 15)).norm(), 0, 1e-9);
  for (int i = 0; i < centred->n_corners; ++i) {
    for (int k = 0; k < 3; ++k) {
      EXPECT_NEAR(centred->corners_mm[i][k],
                  in_file->corners_mm[i][k] - float(report.origin_in_file_mm[k]), 1e-4);
    }
  }
  for (int f = 0; f < centred->n_faces; ++f) {
    // The box about its centroid: caps 15 mm out, sides 20 / sqrt(2) (its corners are 20 mm out).
    const double half = std::abs(centred->faces[f].normal[2]) > 0.5 ? 15.0 : 20.0 / std::sqrt(2.0);
    EXPECT_NEAR(centred->faces[f].offset_mm, half, 1e-4) << f;
  }
}

// A binary STL: 80-byte header, the triangle count, then 50 bytes a triangle.
std::string BinaryStl(uint32_t count, const std::vector<std::array<float, 9>>& triangles) {
  std::string bytes(80, ' ');
  bytes.append(reinterpret_cast<const char*>(&count), 4);
  for (const auto& t : triangles) {
    const float normal[3] = {0, 0, 0};
    bytes.append(reinterpret_cast<const char*>(normal), 12);
    bytes.append(reinterpret_cast<const char*>(t.data()), 36);
    bytes.append(2, '\0');
  }
  return bytes;
}

std::vector<std::array<float, 9>> AsFloat(const std::vector<std::array<double, 9>>& in) {
  std::vector<std::array<float, 9>> out;
  for (const auto& t : in) {
    std::array<float, 9> f{};
    for (int k = 0; k < 9; ++k) f[k] = static_cast<float>(t[k]);
    out.push_back(f);
  }
  return out;
}

std::string Import(const std::string& path) {
  const Result<Model> m = ImportCadModel(path, {});
  return m.ok() ? std::string("ok") : std::string(m.status().message());
}

TEST(CadImport, MalformedFilesAreRefusedClearly) {
  TempDir dir("cad");
  const std::vector<std::array<float, 9>> cube = AsFloat(PrismTriangles(4, 20, 20));
  const std::string whole = BinaryStl(uint32_t(cube.size()), cube);
  std::ofstream(dir.Sub("whole.stl"), std::ios::binary) << whole;
  EXPECT_EQ(Import(dir.Sub("whole.stl")), "ok");

  std::ofstream(dir.Sub("truncated.stl"), std::ios::binary) << whole.substr(0, whole.size() - 70);
  std::string message = Import(dir.Sub("truncated.stl"));
  EXPECT_NE(message.find("not a readable STL file"), std::string::npos) << message;

  std::ofstream(dir.Sub("lies.stl"), std::ios::binary) << BinaryStl(10000000, cube);
  message = Import(dir.Sub("lies.stl"));
  EXPECT_NE(message.find("not a readable STL file"), std::string::npos) << message;

  std::vector<std::array<float, 9>> nan = cube;
  nan[3][4] = std::nanf("");
  std::ofstream(dir.Sub("nan.stl"), std::ios::binary) << BinaryStl(uint32_t(nan.size()), nan);
  message = Import(dir.Sub("nan.stl"));
  EXPECT_NE(message.find("non-finite vertex coordinate"), std::string::npos) << message;

  const std::vector<std::array<float, 9>> many = AsFloat(PrismTriangles(300, 20, 20));
  std::ofstream(dir.Sub("many.stl"), std::ios::binary) << BinaryStl(uint32_t(many.size()), many);
  message = Import(dir.Sub("many.stl"));
  EXPECT_NE(message.find("1196 triangles; at most 512"), std::string::npos) << message;

  // Ten million triangles (500 MB) are refused from the file's size: a sparse file, never read.
  { std::ofstream(dir.Sub("huge.stl"), std::ios::binary) << BinaryStl(10000000, {}); }
  ASSERT_EQ(truncate(dir.Sub("huge.stl").c_str(), 84 + 50L * 10000000), 0);
  message = Import(dir.Sub("huge.stl"));
  EXPECT_NE(message.find("huge.stl"), std::string::npos) << message;
  EXPECT_NE(message.find("8388608"), std::string::npos) << message;

  ASSERT_EQ(mkfifo(dir.Sub("fifo.stl").c_str(), 0600), 0);
  message = Import(dir.Sub("fifo.stl"));
  EXPECT_NE(message.find("FIFO"), std::string::npos) << message;

  std::ofstream(dir.Sub("text.ply")) << "this is no PLY\n";
  message = Import(dir.Sub("text.ply"));
  EXPECT_NE(message.find("not a readable PLY file"), std::string::npos) << message;
}

}  // namespace
}  // namespace sh
