#include "tools/tablegen/model_symmetry.hpp"

#include <Eigen/Geometry>

namespace sh {
namespace {

// Frame (rows = axes) of three non-collinear points, origin ignored.
Eigen::Matrix3f Axes(const Eigen::Vector3f& a, const Eigen::Vector3f& b, const Eigen::Vector3f& c) {
  const Eigen::Vector3f x = (b - a).normalized();
  const Eigen::Vector3f y = ((c - a) - (c - a).dot(x) * x).normalized();
  Eigen::Matrix3f R;
  R.row(0) = x;
  R.row(1) = y;
  R.row(2) = x.cross(y);
  return R;
}

int FindCorner(const Model& m, const Eigen::Vector3f& p, float tol) {
  for (int i = 0; i < m.n_corners; ++i) {
    if ((m.corner(i) - p).norm() < tol) return i;
  }
  return -1;
}

}  // namespace

std::vector<SymmetryAction> FindSymmetries(const Model& m, float tol) {
  std::vector<SymmetryAction> result;
  // Reference triple: corner 0, the farthest corner from it, and the corner farthest from
  // their line (well conditioned).
  int i1 = 1, i2 = 2;
  float best = -1;
  for (int i = 1; i < m.n_corners; ++i) {
    const float d = (m.corner(i) - m.corner(0)).norm();
    if (d > best) best = d, i1 = i;
  }
  best = -1;
  const Eigen::Vector3f x = (m.corner(i1) - m.corner(0)).normalized();
  for (int i = 1; i < m.n_corners; ++i) {
    const Eigen::Vector3f w = m.corner(i) - m.corner(0);
    const float d = (w - w.dot(x) * x).norm();
    if (i != i1 && d > best) best = d, i2 = i;
  }
  const Eigen::Vector3f p0 = m.corner(0), p1 = m.corner(i1), p2 = m.corner(i2);
  const float d01 = (p1 - p0).norm(), d02 = (p2 - p0).norm(), d12 = (p2 - p1).norm();
  const Eigen::Matrix3f A = Axes(p0, p1, p2);
  for (int a = 0; a < m.n_corners; ++a) {
    for (int b = 0; b < m.n_corners; ++b) {
      if (b == a || std::fabs((m.corner(b) - m.corner(a)).norm() - d01) > tol * 10) continue;
      for (int c = 0; c < m.n_corners; ++c) {
        if (c == a || c == b) continue;
        if (std::fabs((m.corner(c) - m.corner(a)).norm() - d02) > tol * 10 ||
            std::fabs((m.corner(c) - m.corner(b)).norm() - d12) > tol * 10)
          continue;
        // R maps the reference frame onto (a, b, c): x' = R x + t.
        const Eigen::Matrix3f R = Axes(m.corner(a), m.corner(b), m.corner(c)).transpose() * A;
        const Eigen::Vector3f t = m.corner(a) - R * p0;
        SymmetryAction act;
        act.R = R;
        act.corner_map.resize(m.n_corners);
        bool ok = true;
        for (int i = 0; i < m.n_corners && ok; ++i) {
          act.corner_map[i] = FindCorner(m, R * m.corner(i) + t, tol * 10);
          ok = act.corner_map[i] >= 0;
        }
        for (int e = 0; e < m.n_edges && ok; ++e) {
          const int ma = act.corner_map[m.edges[e].a], mb = act.corner_map[m.edges[e].b];
          int found = -1;
          bool flipped = false;
          for (int f = 0; f < m.n_edges; ++f) {
            if (m.edges[f].a == ma && m.edges[f].b == mb) found = f, flipped = false;
            if (m.edges[f].a == mb && m.edges[f].b == ma) found = f, flipped = true;
          }
          ok = found >= 0;
          act.edge_map.push_back(found);
          act.edge_flipped.push_back(flipped);
        }
        if (!ok || t.norm() > tol * 100) continue;
        bool duplicate = false;
        for (const auto& r : result) duplicate |= (r.R - R).norm() < 1e-3f;
        if (duplicate) continue;
        const bool identity = (R - Eigen::Matrix3f::Identity()).norm() < 1e-4f;
        if (identity) {
          result.insert(result.begin(), act);
        } else {
          result.push_back(act);
        }
      }
    }
  }
  return result;
}

void StoreSymmetries(Model& model, const std::vector<SymmetryAction>& actions) {
  model.n_symmetries = 0;
  for (const auto& a : actions) {
    if (model.n_symmetries == kMaxModelSymmetries) break;
    Eigen::Map<Eigen::Matrix<float, 3, 3, Eigen::RowMajor>>(model.symmetries[model.n_symmetries]) =
        a.R;
    ++model.n_symmetries;
  }
}

}  // namespace sh
