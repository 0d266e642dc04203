#include "recog/mono/view_sphere.hpp"

#include <algorithm>
#include <cmath>

#include "recog/base/angles.hpp"

namespace sh {
namespace {

// Fixed direction that no rotation symmetry of a polyhedron keeps in place (irrational-looking
// components, off every axis and diagonal of the reference shapes).
const Eigen::Vector3f kDomainAxis = Eigen::Vector3f(0.3127f, 0.5411f, 0.7809f).normalized();

float PolarDeg(const Eigen::Vector3f& d) {
  return std::acos(std::max(-1.0f, std::min(1.0f, d.z()))) * kRadToDeg;
}

float AzimuthDeg(const Eigen::Vector3f& d) {
  if (std::hypot(d.x(), d.y()) < 1e-6f) return 0.0f;
  float phi = std::atan2(d.y(), d.x()) * kRadToDeg;
  if (phi < 0) phi += 360.0f;
  return phi;
}

}  // namespace

Eigen::Vector3f ViewVector(float theta_deg, float phi_deg) {
  const float t = theta_deg * kDegToRad, p = phi_deg * kDegToRad;
  return {std::sin(t) * std::cos(p), std::sin(t) * std::sin(p), std::cos(t)};
}

int InitialViewGrid(float spacing_deg, ViewDirection* out, int capacity) {
  if (!(spacing_deg > 0.5f && spacing_deg <= 90.0f)) return 0;
  const int n_theta = static_cast<int>(std::lround(180.0f / spacing_deg));
  const float d_theta = 180.0f / static_cast<float>(n_theta);
  int n = 0;
  for (int i = 0; i <= n_theta; ++i) {
    const float theta = d_theta * static_cast<float>(i);
    // Azimuth count proportional to sin(theta): about spacing_deg of arc between neighbours.
    const int n_phi =
        std::max(1, static_cast<int>(std::lround(360.0f * std::sin(theta * kDegToRad) / d_theta)));
    for (int j = 0; j < n_phi; ++j) {
      if (n < capacity) {
        ViewDirection& v = out[n];
        v.theta_deg = theta;
        v.phi_deg = 360.0f * static_cast<float>(j) / static_cast<float>(n_phi);
        v.dir_model = ViewVector(v.theta_deg, v.phi_deg);
        v.spacing_deg = d_theta;
        v.level = 0;
      }
      ++n;
    }
  }
  return n;
}

void RefinementViews(const ViewDirection& view, ViewDirection out[4]) {
  const Eigen::Vector3f d = view.dir_model.normalized();
  // Tangent frame: along increasing theta and increasing phi; fixed axes at the poles.
  Eigen::Vector3f e_phi(-d.y(), d.x(), 0.0f);
  if (e_phi.norm() < 1e-4f) {
    e_phi = Eigen::Vector3f(0, 1, 0);
  } else {
    e_phi.normalize();
  }
  const Eigen::Vector3f e_theta = e_phi.cross(d).normalized();
  const float half = 0.5f * view.spacing_deg * kDegToRad;
  const float step = std::tan(half);
  const float signs[4][2] = {{1, 1}, {1, -1}, {-1, 1}, {-1, -1}};
  for (int k = 0; k < 4; ++k) {
    const Eigen::Vector3f c =
        (d + step * (signs[k][0] * e_theta + signs[k][1] * e_phi)).normalized();
    out[k].dir_model = c;
    out[k].theta_deg = PolarDeg(c);
    out[k].phi_deg = AzimuthDeg(c);
    out[k].spacing_deg = 0.5f * view.spacing_deg;
    out[k].level = static_cast<uint8_t>(view.level + 1);
  }
}

bool InSymmetryDomain(const Model& model, const Eigen::Vector3f& dir_model, float margin_deg) {
  // The part kept is where no symmetry moves the view further along the axis w:
  // f_S(d) = (S^T w - w) . d <= 0 for every S. f_S changes by at most |S^T w - w| per radian of
  // turning d, so a view within margin_deg of that part has f_S(d) <= |S^T w - w| * margin.
  const float margin_rad = margin_deg * kDegToRad;
  for (int k = 1; k < model.n_symmetries; ++k) {
    const Eigen::Vector3f g = model.symmetry(k).transpose() * kDomainAxis - kDomainAxis;
    if (g.dot(dir_model) > g.norm() * margin_rad) return false;
  }
  return true;
}

}  // namespace sh
