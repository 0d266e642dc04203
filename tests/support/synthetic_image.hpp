// Synthetic grey images with known geometry for the image-feature tests and benchmarks: filled
// polygons rendered with area anti-aliasing (supersampling), an optional Gaussian blur (optics)
// and Gaussian noise (sensor). Pixel (x, y) covers [x - 0.5, x + 0.5] x [y - 0.5, y + 0.5].
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include "recog/image/image.hpp"

namespace sh::testing {

struct Point2 {
  double x, y;
};

struct Polygon {
  std::vector<Point2> vertices;  // in order, either orientation
  double intensity = 200.0;
};

// One straight side of a polygon: what an edge and line detector should find.
struct Side {
  Point2 a, b;
  double length() const { return std::hypot(b.x - a.x, b.y - a.y); }
};

inline std::vector<Side> SidesOf(const std::vector<Polygon>& polys) {
  std::vector<Side> sides;
  for (const Polygon& p : polys) {
    for (size_t i = 0; i < p.vertices.size(); ++i) {
      sides.push_back({p.vertices[i], p.vertices[(i + 1) % p.vertices.size()]});
    }
  }
  return sides;
}

class SyntheticImage {
 public:
  SyntheticImage(int width, int height, double background)
      : width_(width), height_(height), value_(size_t(width) * height, background) {}

  int width() const { return width_; }
  int height() const { return height_; }

  // Paints the polygon over what is there, weighted by the covered fraction of each pixel.
  void Fill(const Polygon& poly, int samples_per_axis = 8) {
    double x0 = 1e9, y0 = 1e9, x1 = -1e9, y1 = -1e9;
    for (const Point2& p : poly.vertices) {
      x0 = std::min(x0, p.x);
      y0 = std::min(y0, p.y);
      x1 = std::max(x1, p.x);
      y1 = std::max(y1, p.y);
    }
    const int px0 = std::max(0, int(std::floor(x0)) - 1),
              py0 = std::max(0, int(std::floor(y0)) - 1);
    const int px1 = std::min(width_ - 1, int(std::ceil(x1)) + 1);
    const int py1 = std::min(height_ - 1, int(std::ceil(y1)) + 1);
    const int s = samples_per_axis;
    for (int y = py0; y <= py1; ++y) {
      for (int x = px0; x <= px1; ++x) {
        int inside = 0;
        for (int j = 0; j < s; ++j) {
          for (int i = 0; i < s; ++i) {
            inside += Contains(poly, x - 0.5 + (i + 0.5) / s, y - 0.5 + (j + 0.5) / s) ? 1 : 0;
          }
        }
        const double f = double(inside) / (s * s);
        double& v = value_[size_t(y) * width_ + x];
        v = (1.0 - f) * v + f * poly.intensity;
      }
    }
  }

  void Blur(double sigma) {
    if (sigma <= 0) return;
    const int r = int(std::ceil(3 * sigma));
    std::vector<double> k(2 * r + 1);
    double sum = 0;
    for (int i = -r; i <= r; ++i) sum += k[i + r] = std::exp(-0.5 * i * i / (sigma * sigma));
    for (double& v : k) v /= sum;
    std::vector<double> tmp(value_.size());
    for (int y = 0; y < height_; ++y) {
      for (int x = 0; x < width_; ++x) {
        double a = 0;
        for (int i = -r; i <= r; ++i) a += k[i + r] * at(std::clamp(x + i, 0, width_ - 1), y);
        tmp[size_t(y) * width_ + x] = a;
      }
    }
    for (int y = 0; y < height_; ++y) {
      for (int x = 0; x < width_; ++x) {
        double a = 0;
        for (int i = -r; i <= r; ++i) {
          a += k[i + r] * tmp[size_t(std::clamp(y + i, 0, height_ - 1)) * width_ + x];
        }
        value_[size_t(y) * width_ + x] = a;
      }
    }
  }

  void AddNoise(double sigma, uint32_t seed) {
    std::mt19937 rng(seed);
    std::normal_distribution<double> n(0.0, sigma);
    for (double& v : value_) v += n(rng);
  }

  // A mottled surface, as a table's grain: white noise blurred at blur_px, scaled to a standard
  // deviation of `amplitude` grey levels and added.
  void AddMottle(double amplitude, double blur_px, uint32_t seed) {
    SyntheticImage field(width_, height_, 0.0);
    field.AddNoise(1.0, seed);
    field.Blur(blur_px);
    double sum2 = 0;
    for (double v : field.value_) sum2 += v * v;
    const double scale = amplitude / std::sqrt(sum2 / static_cast<double>(value_.size()));
    for (size_t i = 0; i < value_.size(); ++i) value_[i] += scale * field.value_[i];
  }

  // Independent uniform grey values: the worst case for every detector.
  void FillUniformNoise(uint32_t seed) {
    std::mt19937 rng(seed);
    std::uniform_int_distribution<int> u(0, 255);
    for (double& v : value_) v = u(rng);
  }

  double at(int x, int y) const { return value_[size_t(y) * width_ + x]; }

  // 8-bit copy (rounded, saturated) into `pixels`, returned as a view.
  ConstGrayView ToGray(std::vector<uint8_t>& pixels) const {
    pixels.resize(value_.size());
    for (size_t i = 0; i < value_.size(); ++i) {
      pixels[i] = uint8_t(std::clamp(std::lround(value_[i]), 0L, 255L));
    }
    return {pixels.data(), width_, height_, width_};
  }

  static bool Contains(const Polygon& poly, double x, double y) {
    bool in = false;
    const size_t n = poly.vertices.size();
    for (size_t i = 0, j = n - 1; i < n; j = i++) {
      const Point2& a = poly.vertices[i];
      const Point2& b = poly.vertices[j];
      if ((a.y > y) != (b.y > y) && x < (b.x - a.x) * (y - a.y) / (b.y - a.y) + a.x) in = !in;
    }
    return in;
  }

 private:
  int width_, height_;
  std::vector<double> value_;
};

// Distance from a point to the segment ab.
inline double SegmentDistance(Point2 p, Point2 a, Point2 b) {
  const double dx = b.x - a.x, dy = b.y - a.y;
  const double len2 = dx * dx + dy * dy;
  double t = len2 > 0 ? ((p.x - a.x) * dx + (p.y - a.y) * dy) / len2 : 0.0;
  t = std::clamp(t, 0.0, 1.0);
  return std::hypot(p.x - (a.x + t * dx), p.y - (a.y + t * dy));
}

// A scene of several convex and non-convex polygons at generic angles, scaled to the image size.
inline std::vector<Polygon> TestScene(int width, int height, double intensity) {
  const double sx = width / 756.0, sy = height / 581.0;
  auto P = [&](double x, double y) { return Point2{x * sx, y * sy}; };
  std::vector<Polygon> polys;
  polys.push_back({{P(80.3, 90.7), P(300.2, 120.4), P(260.6, 300.1), P(70.4, 250.9)}, intensity});
  polys.push_back({{P(420.5, 60.2), P(640.8, 110.3), P(520.1, 260.7)}, intensity});
  polys.push_back({{P(380.2, 330.6), P(560.4, 310.3), P(700.7, 420.2), P(600.3, 540.5),
                    P(450.6, 520.8), P(400.1, 450.4)},
                   intensity});
  polys.push_back({{P(90.5, 360.1), P(250.3, 340.8), P(300.9, 420.3), P(230.2, 440.6),
                    P(200.7, 530.4), P(110.1, 500.2)},
                   intensity * 0.8});
  return polys;
}

// TestScene (intensity 190 on 40) at width x height, blurred 0.7 px, with Gaussian noise of
// noise_sigma grey levels: the detectors' test image at a camera's size, viewing `pixels`.
inline ConstGrayView NoisyTestScene(int width, int height, double noise_sigma, uint32_t seed,
                                    std::vector<uint8_t>& pixels) {
  SyntheticImage synth(width, height, 40.0);
  for (const Polygon& p : TestScene(width, height, 190.0)) synth.Fill(p);
  synth.Blur(0.7);
  synth.AddNoise(noise_sigma, seed);
  return synth.ToGray(pixels);
}

}  // namespace sh::testing
