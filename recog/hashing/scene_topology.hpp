// Scene topology for ordering scene bases: which lines end at each point (corners of a
// polyhedron are where edges end), how many of a line's ends meet another line, and whether an
// edge runs from a line to a point. Built once per scene; statically sized.
#pragma once

#include <Eigen/Core>
#include <cstdint>

#include "recog/hashing/scene_grid.hpp"
#include "recog/hashing/scene_state.hpp"
#include "recog/scene/scene.hpp"

namespace sh {

// Not zeroed on creation: per-scene arrays, written by Build before they are read.
class SceneTopology {  // NOLINT(cppcoreguidelines-pro-type-member-init)
 public:
  static constexpr int kMaxIncidentLines = 4;

  // connect_tolerance_mm: a line this close to a point or line meets it; junction_reach_mm: an
  // edge's detected end lies this close to its corner. `scratch` holds 2 * lines positions.
  void Build(const SceneState& state, float connect_tolerance_mm, float junction_reach_mm,
             Eigen::Vector3f* scratch);

  // A corner: some active line passes near the point with one of its ends close by.
  bool IsJunction(int point) const { return incident_count_[point] > 0; }
  int IncidentCount(int point) const { return incident_count_[point]; }
  int IncidentLine(int point, int k) const { return incident_[point][k]; }
  // How many of the line's two ends are corners where another line ends too.
  int LineEndJoins(int line) const { return line_end_joins_[line]; }
  // True if an edge runs from the line to the point: a line incident to the point meets the
  // line near its supported segment (corner-edge-corner, a polyhedron's outline).
  bool Connected(int line, int point) const;
  // True if the infinite lines meet (closest approach within 1.5 connect tolerances); t_first
  // receives the meeting point's parameter along the first line.
  bool LinesMeet(int first, int second, float* t_first) const;

 private:
  void FindIncidentLines();
  void FindLineEndJoins();

  SceneState state_;
  float connect_tolerance_mm_ = 0.0f;
  float junction_reach_mm_ = 0.0f;
  SceneGrid endpoint_grid_;  // item 2i, 2i+1: end points a, b of line i
  int16_t incident_[kMaxScenePoints][kMaxIncidentLines];  // lines ending at each point
  uint8_t incident_count_[kMaxScenePoints];
  uint8_t line_end_joins_[kMaxSceneLines];  // 0..2 ends where another line ends too
};

}  // namespace sh
