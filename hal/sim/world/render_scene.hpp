// What the simulator camera sees: reference objects lying on a table, two point lights, and the
// table's finish. Frames: the table frame has z up and the table surface at z = 0 (millimetres);
// camera frames follow OpenCV (x right, y down, z forward).
#pragma once

#include <Eigen/Core>
#include <cstdint>

#include "recog/base/vector.hpp"
#include "recog/geometry/rigid_transform.hpp"

namespace sh::render {

inline constexpr int kMaxRenderObjects = 16;

enum class Background : uint8_t {
  kDark,   // dark matte table, bright objects
  kLight,  // light table with a faint mirror reflection of the objects
};

struct PrintedSurface;

struct SceneObject {
  uint16_t model_index = 0;  // into the model array passed to the renderer
  RigidTransform table_T_model;
  float albedo = 0.8f;  // diffuse reflectance in [0, 1]
  // Diffuse colour (MTL Kd, linear R, G, B in [0, 1]) that multiplies the albedo per channel;
  // white for the grey objects. Highlights stay white (the lights' colour).
  Eigen::Vector3f colour = Eigen::Vector3f::Ones();
  // The model's print (printed_surface.hpp), which multiplies the albedo; null: plain.
  const PrintedSurface* print = nullptr;
};

struct PointLight {
  Eigen::Vector3f position_table_mm = Eigen::Vector3f(0, 0, 800);
  float intensity = 0.5f;  // irradiance scale at normal incidence (no distance fall-off)
};

// NOLINTNEXTLINE(bugprone-reserved-identifier): clang-tidy 14 names the implicit array copy's index
struct RenderScene {
  Vector<SceneObject, kMaxRenderObjects> objects;
  PointLight lights[2];
  float ambient = 0.15f;
  RigidTransform left_T_table;  // pose of the table in the left camera frame
  Background background = Background::kDark;
  float noise_sigma = 1.5f;  // sensor noise, grey levels (0 for none)
  uint64_t seed = 0;         // noise seed; the same seed gives the same bytes
  int supersampling = 3;     // samples per axis in pixels crossed by an edge or shadow border
};

}  // namespace sh::render
