// Models for the tests: records built in code from vertex and face lists (the same shapes as
// models/cube.obj and models/star.obj), and the reference models read from models/.
#pragma once

#include <Eigen/Core>
#include <array>
#include <string>
#include <vector>

#include "recog/base/status.hpp"
#include "recog/model/model.hpp"

namespace sh::testing {

// Faces list corner indices (0-based) counter-clockwise seen from outside. Edges, normals
// (Newell's method, valid for non-convex faces) and plane offsets are derived.
Model MakeModel(const char* name, const std::vector<Eigen::Vector3f>& corners,
                const std::vector<std::vector<int>>& faces);

// Prism over a polygon given counter-clockwise in the xy plane, from z = -h/2 to z = +h/2.
Model MakePrism(const char* name, const std::vector<Eigen::Vector2f>& outline, float height_mm);

// One of the reference models of models/ (tests run from the project root), through the one
// model loader (tables/model_files.hpp).
Result<Model> LoadReferenceModel(const char* stem);
// The text of models/<stem>.obj ("" when missing), for the parser tests.
std::string ReadModelText(const std::string& stem);

// OBJ text of a 60 x 60 x 10 mm plate (z -5 .. 5) with a 20 x 20 mm square hole through it; its
// top and bottom are four quads each, which merge into one face with a hole.
std::string PlateWithHoleObj();

// A closed n-sided prism as triangles (x0 y0 z0 x1 y1 z1 x2 y2 z2), radius r, z from 0 to h,
// wound counter-clockwise from outside: the triangle soup of a CAD export.
std::vector<std::array<double, 9>> PrismTriangles(int n, double r, double h);
// An ASCII STL of the given triangles.
void WriteAsciiStl(const std::string& path, const std::vector<std::array<double, 9>>& triangles);

Model CubeModel();  // 30 x 30 mm base, 40 mm tall
Model StarModel();  // five-pointed star prism, radii 34 / 22 mm, 20 mm tall

}  // namespace sh::testing
