// The hidden-object mask against a float reference: a carton-sized box at many poses before a
// strongly distorted camera, its surface sampled densely and projected point by point. Every
// projected surface point must be hidden (the hull follows the curved edge images), and every
// hidden pixel must lie within the margin of the projected surface; corner discs hide around the
// corners and not between them; the edge map is cleared exactly where Hides() says; a full mask
// and objects behind the camera are refused, and corners past the disc capacity are counted.
#include "recog/pipeline/hidden_mask.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstring>
#include <random>
#include <string>
#include <vector>

#include "recog/model/obj_model.hpp"

namespace sh {
namespace {

// A box of w x d x h mm (the cereal carton's size), corner at the origin.
Model Box(float w, float d, float h) {
  char text[512];
  std::snprintf(text, sizeof(text),
                "v 0 0 0\nv %g 0 0\nv %g %g 0\nv 0 %g 0\nv 0 0 %g\nv %g 0 %g\nv %g %g %g\n"
                "v 0 %g %g\nf 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf 4 1 5 8\n",
                w, w, d, d, h, w, h, w, d, h, d, h);
  Result<Model> m = ParseObjModel(text, std::strlen(text), "box");
  EXPECT_TRUE(m.ok()) << m.status().message();
  return m.ok() ? *m : Model{};
}

// A 1280 x 1024 camera with strong barrel distortion (edges bow by several pixels).
ViewCamera Camera() {
  ViewCamera v;
  v.intrinsics.width = 1280;
  v.intrinsics.height = 1024;
  v.intrinsics.fx = v.intrinsics.fy = 1100;
  v.intrinsics.cx = 650;
  v.intrinsics.cy = 500;
  v.intrinsics.k1 = -0.25;
  v.intrinsics.k2 = 0.1;
  v.intrinsics.p1 = 0.001;
  v.intrinsics.p2 = -0.0015;
  return v;
}

RigidTransform RandomPose(std::mt19937& rng) {
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  const Eigen::Quaternionf q = Eigen::Quaternionf(u(rng), u(rng), u(rng), u(rng)).normalized();
  RigidTransform T;
  T.R = q.toRotationMatrix();
  // Anywhere in the image, out to the corners where the distortion is strongest.
  T.t_mm = {160.0f * u(rng), 130.0f * u(rng), 330.0f + 60.0f * u(rng)};
  return T;
}

// Pixels of points sampled every ~0.5 mm over the box's six faces.
std::vector<Eigen::Vector2d> ProjectedSurface(const ViewCamera& cam, const Eigen::Vector3f& size,
                                              const RigidTransform& T) {
  std::vector<Eigen::Vector2d> out;
  for (int axis = 0; axis < 3; ++axis) {
    const int u_axis = (axis + 1) % 3, v_axis = (axis + 2) % 3;
    const int nu = int(size[u_axis] * 2) + 1, nv = int(size[v_axis] * 2) + 1;
    for (int side = 0; side < 2; ++side) {
      for (int i = 0; i <= nu; ++i) {
        for (int j = 0; j <= nv; ++j) {
          Eigen::Vector3f p;
          p[axis] = side * size[axis];
          p[u_axis] = size[u_axis] * float(i) / float(nu);
          p[v_axis] = size[v_axis] * float(j) / float(nv);
          Eigen::Vector2d px;
          if (ProjectToPixel(cam.intrinsics, (T * p).cast<double>(), &px)) out.push_back(px);
        }
      }
    }
  }
  return out;
}

TEST(HiddenMask, CoversTheProjectedBoxAndNoMoreThanTheMargin) {
  const Eigen::Vector3f size(100, 70, 30);
  const Model box = Box(size.x(), size.y(), size.z());
  const ViewCamera cam = Camera();
  const float margin_px = 4.0f;
  std::mt19937 rng(5);
  int tested = 0;
  for (int trial = 0; trial < 20; ++trial) {
    const RigidTransform T = RandomPose(rng);
    static HiddenMask mask;
    mask.Clear();
    ASSERT_TRUE(mask.Add(cam, {&box, T}, margin_px));
    const std::vector<Eigen::Vector2d> surface = ProjectedSurface(cam, size, T);
    // Coverage: every surface point is hidden, with no help from the margin's slack beyond
    // 0.5 px (what straight hull edges between samples 1/8 of an edge apart may cut off).
    static HiddenMask tight;
    tight.Clear();
    ASSERT_TRUE(tight.Add(cam, {&box, T}, 0.5f));
    double x_min = 1e9, x_max = -1e9, y_min = 1e9, y_max = -1e9;
    for (const Eigen::Vector2d& p : surface) {
      ASSERT_TRUE(tight.Hides(float(p.x()), float(p.y())))
          << "trial " << trial << " point " << p.transpose();
      x_min = std::min(x_min, p.x());
      x_max = std::max(x_max, p.x());
      y_min = std::min(y_min, p.y());
      y_max = std::max(y_max, p.y());
    }
    // Tightness: every hidden pixel around the box lies within the margin of the surface (the
    // convex box's silhouette is its surface's projection), up to the bounding box's clipping of
    // the corners' mitres (at most margin * sqrt(2)) and the samples' spacing (under 2 px).
    const int w = cam.intrinsics.width, h = cam.intrinsics.height;
    std::vector<uint8_t> on_surface(size_t(w) * h, 0);
    for (const Eigen::Vector2d& p : surface) {
      const int x = int(std::lround(p.x())), y = int(std::lround(p.y()));
      if (x >= 0 && y >= 0 && x < w && y < h) on_surface[size_t(y) * w + x] = 1;
    }
    const double reach = margin_px * std::sqrt(2.0) + 2.0;
    const int r = int(std::ceil(reach));
    for (int y = std::max(r, int(y_min) - 12); y <= std::min(h - 1 - r, int(y_max) + 12); y += 2) {
      for (int x = std::max(r, int(x_min) - 12); x <= std::min(w - 1 - r, int(x_max) + 12);
           x += 2) {
        if (!mask.Hides(float(x), float(y))) continue;
        bool near = false;
        for (int dy = -r; dy <= r && !near; ++dy) {
          for (int dx = -r; dx <= r && !near; ++dx) {
            near = dx * dx + dy * dy <= reach * reach && on_surface[size_t(y + dy) * w + x + dx];
          }
        }
        ASSERT_TRUE(near) << "trial " << trial << " pixel " << x << "," << y;
        ++tested;
      }
    }
  }
  EXPECT_GT(tested, 10000);
}

TEST(HiddenMask, ClearsTheEdgeMapExactlyWhereItHides) {
  const Model box = Box(60, 40, 25);
  const ViewCamera cam = Camera();
  std::mt19937 rng(11);
  static HiddenMask mask;
  mask.Clear();
  // Two grown silhouettes and one with corner discs instead of a margin.
  for (int i = 0; i < 2; ++i) ASSERT_TRUE(mask.Add(cam, {&box, RandomPose(rng)}, 3.0f));
  ASSERT_TRUE(mask.Add(cam, {&box, RandomPose(rng)}, 0.0f, 6.0f));
  const int w = cam.intrinsics.width, h = cam.intrinsics.height;
  std::vector<uint8_t> edge(size_t(w) * h, 255), orientation(edge.size(), 0);
  const EdgeMapView view{{edge.data(), w, h, w}, {orientation.data(), w, h, w}};
  const uint32_t cleared = mask.ClearEdges(view);
  uint32_t hidden = 0, mismatches = 0;
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const bool hides = mask.Hides(float(x), float(y));
      hidden += hides;
      mismatches += hides != (edge[size_t(y) * w + x] == 0);
    }
  }
  EXPECT_GT(hidden, 1000u);
  // Overlapping regions clear a pixel once: the count is of pixels, not of regions.
  EXPECT_EQ(cleared, hidden);
  EXPECT_EQ(mismatches, 0u);
  // Nothing left to clear the second time.
  EXPECT_EQ(mask.ClearEdges(view), 0u);
}

// Corner discs hide each projected corner's surroundings, off the outline too, and leave the
// outline's surroundings between corners to the search, which a margin as wide would hide.
TEST(HiddenMask, CornerDiscsHideTheCornersAndNotTheOutlineBetween) {
  const Model box = Box(100, 70, 30);
  const ViewCamera cam = Camera();
  const float radius_px = 4.0f;
  std::mt19937 rng(7);
  int near_corner = 0, between = 0;
  for (int trial = 0; trial < 10; ++trial) {
    const RigidTransform T = RandomPose(rng);
    static HiddenMask discs, hull, grown;
    discs.Clear();
    hull.Clear();
    grown.Clear();
    ASSERT_TRUE(discs.Add(cam, {&box, T}, 0.0f, radius_px));
    ASSERT_TRUE(hull.Add(cam, {&box, T}, 0.0f));
    ASSERT_TRUE(grown.Add(cam, {&box, T}, radius_px));
    std::vector<Eigen::Vector2f> corners;
    for (int i = 0; i < box.n_corners; ++i) {
      Eigen::Vector2d px;
      ASSERT_TRUE(ProjectToPixel(cam.intrinsics, (T * box.corner(i)).cast<double>(), &px));
      corners.push_back(px.cast<float>());
    }
    // Around each corner, within the radius: hidden.
    for (const Eigen::Vector2f& c : corners) {
      for (int k = 0; k < 16; ++k) {
        const float a = 0.3927f * float(k), d = 0.95f * radius_px;
        const Eigen::Vector2f p = c + d * Eigen::Vector2f(std::cos(a), std::sin(a));
        ASSERT_TRUE(discs.Hides(p.x(), p.y())) << "trial " << trial << " at " << p.transpose();
        ++near_corner;
      }
    }
    // In the margin's band around the outline, away from every corner: not hidden.
    for (int y = 0; y < cam.intrinsics.height; y += 2) {
      for (int x = 0; x < cam.intrinsics.width; x += 2) {
        const float xf = float(x), yf = float(y);
        if (!grown.Hides(xf, yf) || hull.Hides(xf, yf)) continue;
        float nearest2 = 1e9f;
        for (const Eigen::Vector2f& c : corners) {
          nearest2 = std::min(nearest2, (c - Eigen::Vector2f(xf, yf)).squaredNorm());
        }
        if (nearest2 <= (radius_px + 0.5f) * (radius_px + 0.5f)) continue;
        ASSERT_FALSE(discs.Hides(xf, yf)) << "trial " << trial << " at " << x << "," << y;
        ++between;
      }
    }
  }
  EXPECT_EQ(near_corner, 10 * 8 * 16);
  EXPECT_GT(between, 500);
}

// A prism of `n` sides (2 n corners), radius 20 mm, height 10 mm.
Model Prism(int n) {
  std::string text;
  char line[96];
  for (int z = 0; z < 2; ++z) {
    for (int i = 0; i < n; ++i) {
      const double a = 2.0 * M_PI * i / n;
      std::snprintf(line, sizeof(line), "v %.4f %.4f %d\n", 20 * std::cos(a), 20 * std::sin(a),
                    10 * z);
      text += line;
    }
  }
  for (int z = 0; z < 2; ++z) {
    text += "f";
    for (int i = 0; i < n; ++i) text += " " + std::to_string(z == 0 ? n - i : n + 1 + i);
    text += "\n";
  }
  for (int i = 0; i < n; ++i) {
    const int j = (i + 1) % n;
    std::snprintf(line, sizeof(line), "f %d %d %d %d\n", i + 1, j + 1, n + j + 1, n + i + 1);
    text += line;
  }
  Result<Model> m = ParseObjModel(text.data(), text.size(), "prism");
  EXPECT_TRUE(m.ok()) << m.status().message();
  return m.ok() ? *m : Model{};
}

// Past kMaxHiddenDiscs the corners get no disc; the silhouettes are still added and hidden.
TEST(HiddenMask, CornersPastTheDiscCapacityAreCountedAndTheRegionsKept) {
  const int sides = 40;
  const Model prism = Prism(sides);
  ASSERT_EQ(prism.n_corners, 2 * sides);
  const ViewCamera cam = Camera();
  static HiddenMask mask;
  mask.Clear();
  const int objects = kMaxHiddenDiscs / (2 * sides) + 1;
  for (int i = 0; i < objects; ++i) {
    RigidTransform T;
    T.t_mm = {-150.0f + 50.0f * float(i), 0.0f, 400.0f};
    ASSERT_TRUE(mask.Add(cam, {&prism, T}, 0.0f, 3.0f));
  }
  EXPECT_EQ(mask.size(), size_t(objects));
  EXPECT_EQ(mask.discs_dropped(), uint32_t(objects * 2 * sides - kMaxHiddenDiscs));
  // The last object's centre is hidden by its silhouette.
  Eigen::Vector2d centre;
  RigidTransform last;
  last.t_mm = {-150.0f + 50.0f * float(objects - 1), 0.0f, 405.0f};
  ASSERT_TRUE(ProjectToPixel(cam.intrinsics, last.t_mm.cast<double>(), &centre));
  EXPECT_TRUE(mask.Hides(float(centre.x()), float(centre.y())));
  mask.Clear();
  EXPECT_EQ(mask.discs_dropped(), 0u);
}

TEST(HiddenMask, RefusesWhenFullOrBehindTheCamera) {
  const Model box = Box(60, 40, 25);
  const ViewCamera cam = Camera();
  static HiddenMask mask;
  mask.Clear();
  RigidTransform T;
  T.t_mm = {0, 0, 400};
  for (size_t i = 0; i < kMaxHiddenObjects; ++i) ASSERT_TRUE(mask.Add(cam, {&box, T}, 2.0f));
  EXPECT_FALSE(mask.Add(cam, {&box, T}, 2.0f));
  EXPECT_EQ(mask.size(), kMaxHiddenObjects);
  mask.Clear();
  T.t_mm = {0, 0, -10};  // straddles the camera plane
  EXPECT_FALSE(mask.Add(cam, {&box, T}, 2.0f));
  EXPECT_FALSE(mask.Add(cam, {nullptr, T}, 2.0f));
  EXPECT_EQ(mask.size(), 0u);
  EXPECT_FALSE(mask.Hides(640, 512));
}

}  // namespace
}  // namespace sh
