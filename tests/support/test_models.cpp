#include "tests/support/test_models.hpp"

#include <cmath>
#include <cstring>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <utility>

#include "tables/model_files.hpp"

namespace sh::testing {

Model MakeModel(const char* name, const std::vector<Eigen::Vector3f>& corners,
                const std::vector<std::vector<int>>& faces) {
  Model m;
  std::strncpy(m.name, name, kMaxModelNameLength);
  m.n_corners = static_cast<uint16_t>(corners.size());
  for (size_t i = 0; i < corners.size(); ++i) {
    for (int k = 0; k < 3; ++k) m.corners_mm[i][k] = corners[i][k];
  }
  m.n_faces = static_cast<uint16_t>(faces.size());
  // Directed edge (a -> b) in the counter-clockwise order of a face: the face to its left.
  std::map<std::pair<int, int>, int> directed;
  for (size_t f = 0; f < faces.size(); ++f) {
    ModelFace& face = m.faces[f];
    face.n_vertices = static_cast<uint8_t>(faces[f].size());
    Eigen::Vector3d normal = Eigen::Vector3d::Zero();
    for (size_t k = 0; k < faces[f].size(); ++k) {
      const int a = faces[f][k], b = faces[f][(k + 1) % faces[f].size()];
      face.vertices[k] = static_cast<uint8_t>(a);
      const Eigen::Vector3d pa = corners[a].cast<double>(), pb = corners[b].cast<double>();
      normal += Eigen::Vector3d((pa.y() - pb.y()) * (pa.z() + pb.z()),
                                (pa.z() - pb.z()) * (pa.x() + pb.x()),
                                (pa.x() - pb.x()) * (pa.y() + pb.y()));
      directed[{a, b}] = static_cast<int>(f);
    }
    normal.normalize();
    for (int k = 0; k < 3; ++k) face.normal[k] = static_cast<float>(normal[k]);
    face.offset_mm = static_cast<float>(normal.dot(corners[faces[f][0]].cast<double>()));
  }
  for (const auto& [ab, f] : directed) {
    if (ab.first > ab.second) continue;
    const auto other = directed.find({ab.second, ab.first});
    if (other == directed.end()) continue;  // open mesh: not produced by the shapes here
    ModelEdge& e = m.edges[m.n_edges++];
    e.a = static_cast<uint8_t>(ab.first);
    e.b = static_cast<uint8_t>(ab.second);
    e.face0 = static_cast<uint8_t>(f);
    e.face1 = static_cast<uint8_t>(other->second);
  }
  m.n_symmetries = 1;
  const float identity[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
  std::memcpy(m.symmetries[0], identity, sizeof(identity));
  return m;
}

Model MakePrism(const char* name, const std::vector<Eigen::Vector2f>& outline, float height_mm) {
  const int n = static_cast<int>(outline.size());
  std::vector<Eigen::Vector3f> corners;
  for (int z = 0; z < 2; ++z) {
    for (const Eigen::Vector2f& p : outline) {
      corners.emplace_back(p.x(), p.y(), (z == 0 ? -0.5f : 0.5f) * height_mm);
    }
  }
  std::vector<std::vector<int>> faces;
  std::vector<int> bottom, top;
  for (int i = n - 1; i >= 0; --i) bottom.push_back(i);
  for (int i = 0; i < n; ++i) top.push_back(n + i);
  faces.push_back(bottom);
  faces.push_back(top);
  for (int i = 0; i < n; ++i) {
    const int j = (i + 1) % n;
    faces.push_back({i, j, n + j, n + i});
  }
  return MakeModel(name, corners, faces);
}

std::vector<std::array<double, 9>> PrismTriangles(int n, double r, double h) {
  std::vector<std::array<double, 9>> t;
  auto x = [&](int i) { return r * std::cos(2 * M_PI * i / n); };
  auto y = [&](int i) { return r * std::sin(2 * M_PI * i / n); };
  for (int i = 0; i < n; ++i) {
    const int j = (i + 1) % n;
    t.push_back({x(i), y(i), 0, x(j), y(j), 0, x(j), y(j), h});
    t.push_back({x(i), y(i), 0, x(j), y(j), h, x(i), y(i), h});
    if (i > 0 && j > 0) {
      t.push_back({x(0), y(0), h, x(i), y(i), h, x(j), y(j), h});
      t.push_back({x(0), y(0), 0, x(j), y(j), 0, x(i), y(i), 0});
    }
  }
  return t;
}

void WriteAsciiStl(const std::string& path, const std::vector<std::array<double, 9>>& triangles) {
  std::ofstream out(path);
  out << "solid part\n";
  for (const auto& t : triangles) {
    out << " facet normal 0 0 0\n  outer loop\n";
    for (size_t k = 0; k < 9; k += 3) {
      out << "   vertex " << t[k] << " " << t[k + 1] << " " << t[k + 2] << "\n";
    }
    out << "  endloop\n endfacet\n";
  }
  out << "endsolid part\n";
}

Model CubeModel() { return MakePrism("cube", {{-15, -15}, {15, -15}, {15, 15}, {-15, 15}}, 40.0f); }

Model StarModel() {
  std::vector<Eigen::Vector2f> outline;
  for (int k = 0; k < 10; ++k) {
    const double angle = (90.0 + 36.0 * k) * M_PI / 180.0;
    const double radius = (k % 2 == 0) ? 34.0 : 22.0;
    outline.emplace_back(static_cast<float>(radius * std::cos(angle)),
                         static_cast<float>(radius * std::sin(angle)));
  }
  return MakePrism("star", outline, 20.0f);
}

std::string PlateWithHoleObj() {
  return "v -30 -30 -5\nv 30 -30 -5\nv 30 30 -5\nv -30 30 -5\n"
         "v -30 -30 5\nv 30 -30 5\nv 30 30 5\nv -30 30 5\n"
         "v -10 -10 -5\nv 10 -10 -5\nv 10 10 -5\nv -10 10 -5\n"
         "v -10 -10 5\nv 10 -10 5\nv 10 10 5\nv -10 10 5\n"
         "f 5 6 14 13\nf 6 7 15 14\nf 7 8 16 15\nf 8 5 13 16\n"
         "f 2 1 9 10\nf 3 2 10 11\nf 4 3 11 12\nf 1 4 12 9\n"
         "f 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf 4 1 5 8\n"
         "f 10 9 13 14\nf 11 10 14 15\nf 12 11 15 16\nf 9 12 16 13\n";
}

std::string ReadModelText(const std::string& stem) {
  std::ifstream in("models/" + stem + ".obj", std::ios::binary);
  std::stringstream buffer;
  buffer << in.rdbuf();
  return buffer.str();
}

Result<Model> LoadReferenceModel(const char* stem) {
  return LoadModelFile(std::string("models/") + stem + ".obj");
}

}  // namespace sh::testing
