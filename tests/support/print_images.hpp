// Test images for the texture path: a procedural "print" (grey rectangles, discs, bars and
// strokes on a mid-grey ground, smooth at the pixel scale) that can be sampled at any point, so
// that rotated, scaled and perspective views of it are rendered from the pattern itself rather
// than resampled from another image.
#pragma once

#include <Eigen/Geometry>
#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include "recog/camera/camera_model.hpp"
#include "recog/image/image.hpp"

namespace sh::testing {

class PrintPattern {
 public:
  // A pattern over [0, size_mm]^2 with `shapes` random shapes; coordinates in millimetres.
  PrintPattern(float size_mm, int shapes, uint32_t seed) : size_(size_mm) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> pos(0.0f, size_mm), grey(0.05f, 0.95f);
    std::uniform_real_distribution<float> len(0.02f * size_mm, 0.18f * size_mm);
    std::uniform_real_distribution<float> angle(0.0f, 3.14159265f);
    for (int i = 0; i < shapes; ++i) {
      Shape s;
      s.kind = static_cast<int>(rng() % 3);
      s.cx = pos(rng);
      s.cy = pos(rng);
      s.a = len(rng);
      s.b = len(rng) * (s.kind == 2 ? 0.15f : 1.0f);
      s.angle = angle(rng);
      s.grey = grey(rng);
      shapes_.push_back(s);
    }
  }

  // Grey value on [0, 1] at (x, y) mm, anti-aliased over `blur_mm` (edge ramp width).
  float At(float x, float y, float blur_mm) const {
    float v = 0.5f;
    for (const Shape& s : shapes_) {
      const float dx = x - s.cx, dy = y - s.cy;
      const float c = std::cos(s.angle), sn = std::sin(s.angle);
      const float u = c * dx + sn * dy, w = -sn * dx + c * dy;
      float inside;  // signed distance, positive inside
      if (s.kind == 1) {
        inside = s.a * 0.5f - std::sqrt(dx * dx + dy * dy);
      } else {
        inside = std::min(s.a * 0.5f - std::fabs(u), s.b * 0.5f - std::fabs(w));
      }
      const float t = std::clamp(0.5f + inside / std::max(blur_mm, 1e-3f), 0.0f, 1.0f);
      v = v * (1.0f - t) + s.grey * t;
    }
    return v;
  }

  float size_mm() const { return size_; }

 private:
  struct Shape {
    int kind;
    float cx, cy, a, b, angle, grey;
  };
  float size_;
  std::vector<Shape> shapes_;
};

// A converging stereo rig like the recorded sets' (right camera turned by about 17 degrees,
// mostly about y, 110 mm baseline) with barrel distortion in both lenses.
inline StereoCalibration RotatedStereoRig(int width, int height, double f) {
  StereoCalibration calib;
  for (CameraIntrinsics* c : {&calib.left, &calib.right}) {
    c->width = width;
    c->height = height;
    c->fx = c->fy = f;
    c->cx = 0.5 * width;
    c->cy = 0.5 * height;
    c->k1 = -0.2;
    c->k2 = 0.08;
  }
  calib.right_R_left =
      Eigen::AngleAxisd(0.3, Eigen::Vector3d(0.15, 1.0, 0.5).normalized()).toRotationMatrix();
  calib.right_t_left_mm = {-110, -10, 14};
  return calib;
}

// An 8-bit image with its storage.
struct TestImage {
  int width = 0, height = 0;
  std::vector<uint8_t> pixels;
  TestImage(int w, int h, uint8_t fill = 0)
      : width(w), height(h), pixels(static_cast<size_t>(w) * h, fill) {}
  ConstGrayView view() const { return {pixels.data(), width, height, width}; }
  uint8_t& at(int x, int y) { return pixels[static_cast<size_t>(y) * width + x]; }
};

// Renders the pattern through `pattern_from_pixel` (pixel centre (x, y) -> pattern mm, any
// smooth map), one sample per pixel (the pattern's edge ramp of blur_mm anti-aliases it); pixels
// mapping outside the pattern get `outside`.
template <typename Map>
TestImage RenderPattern(const PrintPattern& p, int w, int h, Map pattern_from_pixel, float blur_mm,
                        uint8_t outside = 20) {
  TestImage img(w, h);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      Eigen::Vector2f q;
      const bool inside = pattern_from_pixel(static_cast<float>(x), static_cast<float>(y), &q) &&
                          q.x() >= 0 && q.y() >= 0 && q.x() <= p.size_mm() && q.y() <= p.size_mm();
      img.at(x, y) = inside
                         ? static_cast<uint8_t>(std::lround(255.0f * p.At(q.x(), q.y(), blur_mm)))
                         : outside;
    }
  }
  return img;
}

}  // namespace sh::testing
