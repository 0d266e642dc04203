#include "recog/hashing/scene_topology.hpp"

#include <cmath>

#include "recog/hashing/basis.hpp"

namespace sh {

void SceneTopology::Build(const SceneState& state, float connect_tolerance_mm,
                          float junction_reach_mm, Eigen::Vector3f* scratch) {
  state_ = state;
  connect_tolerance_mm_ = connect_tolerance_mm;
  junction_reach_mm_ = junction_reach_mm;
  const Scene& s = *state.scene;
  const int nl = int(s.lines.size());
  for (int i = 0; i < nl; ++i) {
    scratch[size_t{2} * i] = s.lines[i].a_mm;
    scratch[size_t{2} * i + 1] = s.lines[i].b_mm;
  }
  endpoint_grid_.Build(scratch, 2 * nl, 5.0f);
  FindIncidentLines();
  FindLineEndJoins();
}

// A corner of a polyhedron is where edges end: a scene point is a junction when some scene
// line passes within connect_tolerance_mm of it and one of that line's supported ends lies
// within junction_reach_mm (edges are rarely detected right up to the corner).
void SceneTopology::FindIncidentLines() {
  const Scene& s = *state_.scene;
  const float tol = connect_tolerance_mm_;
  for (size_t j = 0; j < s.points.size(); ++j) {
    incident_count_[j] = 0;
    if (!state_.point_active[j]) continue;
    const Eigen::Vector3f& p = s.points[j].p_mm;
    endpoint_grid_.ForEachNear(p, junction_reach_mm_, [&](int item) {
      const int m = item / 2;
      if (incident_count_[j] == kMaxIncidentLines || !state_.line_active[m]) return;
      for (int k = 0; k < incident_count_[j]; ++k) {
        if (incident_[j][k] == m) return;
      }
      if (PointLineDistance({s.lines[m].a_mm, state_.line_dir[m]}, p) > tol) return;
      incident_[j][incident_count_[j]++] = int16_t(m);
    });
  }
}

bool SceneTopology::LinesMeet(int first, int second, float* t_first) const {
  const Scene& s = *state_.scene;
  const Eigen::Vector3f &u = state_.line_dir[first], &v = state_.line_dir[second];
  const Eigen::Vector3f w = s.lines[first].a_mm - s.lines[second].a_mm;
  const float b = u.dot(v), d = u.dot(w), e = v.dot(w);
  const float denom = 1.0f - b * b;
  if (denom < 0.05f) return false;  // nearly parallel: no corner
  const float t0 = (b * e - d) / denom, t1 = (e - b * d) / denom;
  const Eigen::Vector3f gap = (s.lines[first].a_mm + t0 * u) - (s.lines[second].a_mm + t1 * v);
  const float tol = 1.5f * connect_tolerance_mm_;
  *t_first = t0;
  return gap.squaredNorm() <= tol * tol;
}

void SceneTopology::FindLineEndJoins() {
  const Scene& s = *state_.scene;
  const float reach = junction_reach_mm_;
  for (size_t i = 0; i < s.lines.size(); ++i) {
    line_end_joins_[i] = 0;
    if (!state_.line_active[i]) continue;
    const float length = s.lines[i].length_mm();
    for (int end = 0; end < 2; ++end) {
      bool joined = false;
      endpoint_grid_.ForEachNear(end ? s.lines[i].b_mm : s.lines[i].a_mm, reach, [&](int item) {
        const int m = item / 2;
        float t = 0.0f;
        if (joined || m == int(i) || !state_.line_active[m] || !LinesMeet(int(i), m, &t)) return;
        joined = end ? std::fabs(t - length) <= reach : std::fabs(t) <= reach;
      });
      line_end_joins_[i] += joined;
    }
  }
}

bool SceneTopology::Connected(int line, int point) const {
  const float reach = junction_reach_mm_;
  const float length = state_.scene->lines[line].length_mm();
  for (int k = 0; k < incident_count_[point]; ++k) {
    const int m = incident_[point][k];
    float t = 0.0f;
    if (m != line && LinesMeet(line, m, &t) && t >= -reach && t <= length + reach) return true;
  }
  return false;
}

}  // namespace sh
