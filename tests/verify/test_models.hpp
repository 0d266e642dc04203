// Model records for the verification tests, built in code from vertex and face lists (the same
// shapes as models/cube.obj and models/star.obj).
#pragma once

#include <Eigen/Core>
#include <vector>

#include "recog/model/model.hpp"

namespace sh::testing {

// Faces list corner indices (0-based) counter-clockwise seen from outside. Edges, normals
// (Newell's method, valid for non-convex faces) and plane offsets are derived.
Model MakeModel(const char* name, const std::vector<Eigen::Vector3f>& corners,
                const std::vector<std::vector<int>>& faces);

// Prism over a polygon given counter-clockwise in the xy plane, from z = -h/2 to z = +h/2.
Model MakePrism(const char* name, const std::vector<Eigen::Vector2f>& outline, float height_mm);

Model CubeModel();  // 30 x 30 mm base, 40 mm tall
Model StarModel();  // five-pointed star prism, radii 34 / 22 mm, 20 mm tall

}  // namespace sh::testing
