#include "tools/overlay.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>

#include "recog/verify/view_camera.hpp"

namespace sh::tools {
namespace {

// 5 x 7 glyphs: one byte per row, top row first, bit 4 = leftmost column.
struct Glyph {
  char c;
  uint8_t rows[7];
};

constexpr Glyph kGlyphs[] = {
    {'a', {0x00, 0x00, 0x0e, 0x01, 0x0f, 0x11, 0x0f}},
    {'b', {0x10, 0x10, 0x1e, 0x11, 0x11, 0x11, 0x1e}},
    {'c', {0x00, 0x00, 0x0e, 0x10, 0x10, 0x11, 0x0e}},
    {'d', {0x01, 0x01, 0x0f, 0x11, 0x11, 0x11, 0x0f}},
    {'e', {0x00, 0x00, 0x0e, 0x11, 0x1f, 0x10, 0x0e}},
    {'f', {0x06, 0x09, 0x08, 0x1c, 0x08, 0x08, 0x08}},
    {'g', {0x00, 0x0f, 0x11, 0x11, 0x0f, 0x01, 0x0e}},
    {'h', {0x10, 0x10, 0x16, 0x19, 0x11, 0x11, 0x11}},
    {'i', {0x04, 0x00, 0x0c, 0x04, 0x04, 0x04, 0x0e}},
    {'j', {0x02, 0x00, 0x06, 0x02, 0x02, 0x12, 0x0c}},
    {'k', {0x10, 0x10, 0x12, 0x14, 0x18, 0x14, 0x12}},
    {'l', {0x0c, 0x04, 0x04, 0x04, 0x04, 0x04, 0x0e}},
    {'m', {0x00, 0x00, 0x1a, 0x15, 0x15, 0x11, 0x11}},
    {'n', {0x00, 0x00, 0x16, 0x19, 0x11, 0x11, 0x11}},
    {'o', {0x00, 0x00, 0x0e, 0x11, 0x11, 0x11, 0x0e}},
    {'p', {0x00, 0x00, 0x1e, 0x11, 0x1e, 0x10, 0x10}},
    {'q', {0x00, 0x00, 0x0f, 0x11, 0x0f, 0x01, 0x01}},
    {'r', {0x00, 0x00, 0x16, 0x19, 0x10, 0x10, 0x10}},
    {'s', {0x00, 0x00, 0x0e, 0x10, 0x0e, 0x01, 0x1e}},
    {'t', {0x08, 0x08, 0x1c, 0x08, 0x08, 0x09, 0x06}},
    {'u', {0x00, 0x00, 0x11, 0x11, 0x11, 0x13, 0x0d}},
    {'v', {0x00, 0x00, 0x11, 0x11, 0x11, 0x0a, 0x04}},
    {'w', {0x00, 0x00, 0x11, 0x11, 0x15, 0x15, 0x0a}},
    {'x', {0x00, 0x00, 0x11, 0x0a, 0x04, 0x0a, 0x11}},
    {'y', {0x00, 0x00, 0x11, 0x11, 0x0f, 0x01, 0x0e}},
    {'z', {0x00, 0x00, 0x1f, 0x02, 0x04, 0x08, 0x1f}},
    {'0', {0x0e, 0x11, 0x13, 0x15, 0x19, 0x11, 0x0e}},
    {'1', {0x04, 0x0c, 0x04, 0x04, 0x04, 0x04, 0x0e}},
    {'2', {0x0e, 0x11, 0x01, 0x02, 0x04, 0x08, 0x1f}},
    {'3', {0x1f, 0x02, 0x04, 0x02, 0x01, 0x11, 0x0e}},
    {'4', {0x02, 0x06, 0x0a, 0x12, 0x1f, 0x02, 0x02}},
    {'5', {0x1f, 0x10, 0x1e, 0x01, 0x01, 0x11, 0x0e}},
    {'6', {0x06, 0x08, 0x10, 0x1e, 0x11, 0x11, 0x0e}},
    {'7', {0x1f, 0x01, 0x02, 0x04, 0x08, 0x08, 0x08}},
    {'8', {0x0e, 0x11, 0x11, 0x0e, 0x11, 0x11, 0x0e}},
    {'9', {0x0e, 0x11, 0x11, 0x0f, 0x01, 0x02, 0x0c}},
    {'-', {0x00, 0x00, 0x00, 0x1f, 0x00, 0x00, 0x00}},
    {'_', {0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x1f}},
    {'.', {0x00, 0x00, 0x00, 0x00, 0x00, 0x0c, 0x0c}},
    {'#', {0x0a, 0x0a, 0x1f, 0x0a, 0x1f, 0x0a, 0x0a}},
    {'(', {0x02, 0x04, 0x08, 0x08, 0x08, 0x04, 0x02}},
    {')', {0x08, 0x04, 0x02, 0x02, 0x02, 0x04, 0x08}},
    {':', {0x00, 0x0c, 0x0c, 0x00, 0x0c, 0x0c, 0x00}},

};

const uint8_t* FindGlyph(char c) {
  if (c >= 'A' && c <= 'Z') c = static_cast<char>(c - 'A' + 'a');
  for (const Glyph& g : kGlyphs) {
    if (g.c == c) return g.rows;
  }
  return nullptr;
}

void Put(ImageView<Rgb8> image, int x, int y, Rgb8 colour) {
  if (image.contains(x, y)) image.at(x, y) = colour;
}

void DrawGlyph(ImageView<Rgb8> image, int x0, int y0, const uint8_t* rows, int scale, Rgb8 colour) {
  for (int gy = 0; gy < 7; ++gy) {
    for (int gx = 0; gx < 5; ++gx) {
      // Unknown characters: a box outline.
      const bool ink =
          rows ? ((rows[gy] >> (4 - gx)) & 1) != 0 : (gx == 0 || gx == 4 || gy == 0 || gy == 6);
      if (!ink) continue;
      for (int sy = 0; sy < scale; ++sy) {
        for (int sx = 0; sx < scale; ++sx)
          Put(image, x0 + gx * scale + sx, y0 + gy * scale + sy, colour);
      }
    }
  }
}

Eigen::Vector3f ModelCentre(const Model& m) {
  Eigen::Vector3f c = Eigen::Vector3f::Zero();
  for (int i = 0; i < m.n_corners; ++i) c += m.corner(i);
  return m.n_corners ? Eigen::Vector3f(c / static_cast<float>(m.n_corners)) : c;
}

}  // namespace

int TextWidth(const char* text, int scale) {
  const int n = static_cast<int>(std::strlen(text));
  return n > 0 ? (6 * n - 1) * scale : 0;
}

void DrawText(ImageView<Rgb8> image, int x, int y, const char* text, int scale, Rgb8 colour) {
  const Rgb8 outline{0, 0, 0};
  for (int pass = 0; pass < 2; ++pass) {
    int cx = x;
    for (const char* p = text; *p != '\0'; ++p, cx += 6 * scale) {
      if (*p == ' ') continue;
      const uint8_t* rows = FindGlyph(*p);
      if (pass == 0) {
        for (int dy = -1; dy <= 1; ++dy) {
          for (int dx = -1; dx <= 1; ++dx) {
            if (dx != 0 || dy != 0) DrawGlyph(image, cx + dx, y + dy, rows, scale, outline);
          }
        }
      } else {
        DrawGlyph(image, cx, y, rows, scale, colour);
      }
    }
  }
}

Rgb8 ObjectColour(int i) {
  static constexpr Rgb8 kColours[] = {{255, 64, 64},  {64, 255, 64},  {80, 160, 255},
                                      {255, 230, 40}, {255, 64, 255}, {40, 255, 255},
                                      {255, 150, 40}, {170, 110, 255}};
  return kColours[i % (sizeof(kColours) / sizeof(kColours[0]))];
}

namespace {

// The left | right halves of an overlay buffer.
struct Halves {
  ImageView<Rgb8> half[2];
};

Result<Halves> SplitOverlay(std::vector<uint8_t>* rgb, int width, int height) {
  if (width % 2 != 0 || rgb->size() != size_t(width) * size_t(height) * 3) {
    return Status::Error(StatusCode::kInvalidArgument, "overlay buffer is not %d x %d RGB", width,
                         height);
  }
  const int w = width / 2;
  Rgb8* data = reinterpret_cast<Rgb8*>(rgb->data());
  return Halves{{{data, w, height, width}, {data + w, w, height, width}}};
}

// The two images side by side, dimmed by `dim_num` / 4 so that coloured marks stand out.
Status DimmedPair(ConstGrayView left, ConstGrayView right, int dim_num, std::vector<uint8_t>* rgb,
                  int* width, int* height) {
  if (left.empty() || right.empty() || left.width != right.width || left.height != right.height) {
    return Status::Error(StatusCode::kInvalidArgument,
                         "overlay needs two non-empty images of the same size");
  }
  const int w = left.width, h = left.height;
  *width = 2 * w;
  *height = h;
  rgb->assign(size_t(*width) * h * 3, 0);
  ImageView<Rgb8> all{reinterpret_cast<Rgb8*>(rgb->data()), *width, h, *width};
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const uint8_t l = static_cast<uint8_t>(left.at(x, y) * dim_num / 4);
      const uint8_t r = static_cast<uint8_t>(right.at(x, y) * dim_num / 4);
      all.at(x, y) = {l, l, l};
      all.at(w + x, y) = {r, r, r};
    }
  }
  return Status::Ok();
}

void DrawSegment(ImageView<Rgb8> image, float x0, float y0, float x1, float y1, Rgb8 colour) {
  const int n = static_cast<int>(std::max(std::fabs(x1 - x0), std::fabs(y1 - y0))) + 1;
  for (int i = 0; i <= n; ++i) {
    const float f = float(i) / float(n);
    Put(image, static_cast<int>(std::lround(x0 + f * (x1 - x0))),
        static_cast<int>(std::lround(y0 + f * (y1 - y0))), colour);
  }
}

}  // namespace

Status DrawLabelledModel(const StereoCalibration& calib, const PosedModel& posed,
                         const PosedModel* occluders, size_t n_occluders, const char* label,
                         Rgb8 colour, std::vector<uint8_t>* rgb, int width, int height) {
  SH_ASSIGN_OR_RETURN(const Halves halves, SplitOverlay(rgb, width, height));
  const ViewCamera views[2] = {LeftView(calib), RightView(calib)};
  for (int v = 0; v < 2; ++v) {
    SH_RETURN_IF_ERROR(
        DrawPosedModel(views[v], posed, occluders, n_occluders, halves.half[v], colour));
    const Eigen::Vector3f centre =
        views[v].cam_T_left * (posed.cam_T_model * ModelCentre(*posed.model));
    Eigen::Vector2d px;
    if (!ProjectToPixel(views[v].intrinsics, centre.cast<double>(), &px)) continue;
    const int scale = 2;
    DrawText(halves.half[v], static_cast<int>(px.x()) - TextWidth(label, scale) / 2,
             static_cast<int>(px.y()) - 7 * scale / 2, label, scale, colour);
  }
  return Status::Ok();
}

Status BuildPosedOverlay(const StereoCalibration& calib, const PosedModel* posed, size_t n,
                         ConstGrayView left, ConstGrayView right, std::vector<uint8_t>* rgb,
                         int* width, int* height) {
  SH_RETURN_IF_ERROR(DimmedPair(left, right, 3, rgb, width, height));
  for (size_t i = 0; i < n; ++i) {
    // Every other recognised object may hide this one (at most kMaxOccluders of them).
    PosedModel occluders[kMaxOccluders];
    size_t n_occluders = 0;
    for (size_t k = 0; k < n && n_occluders < kMaxOccluders; ++k) {
      if (k != i) occluders[n_occluders++] = posed[k];
    }
    SH_RETURN_IF_ERROR(DrawLabelledModel(calib, posed[i], occluders, n_occluders,
                                         posed[i].model->name, ObjectColour(static_cast<int>(i)),
                                         rgb, *width, *height));
  }
  return Status::Ok();
}

Status BuildOverlay(const Pipeline& pipeline, const PipelineResult& result, ConstGrayView left,
                    ConstGrayView right, std::vector<uint8_t>* rgb, int* width, int* height) {
  const ModelSet& models = pipeline.models();
  const size_t n = result.objects.size();
  PosedModel posed[kMaxObjects];
  for (size_t i = 0; i < n; ++i) {
    posed[i] = {&models.model(result.objects[i].model), result.objects[i].cam_T_model};
  }
  return BuildPosedOverlay(pipeline.calibration(), posed, n, left, right, rgb, width, height);
}

Status BuildFeatureOverlay(const Pipeline& pipeline, ConstGrayView left, ConstGrayView right,
                           std::vector<uint8_t>* rgb, int* width, int* height) {
  SH_RETURN_IF_ERROR(DimmedPair(left, right, 2, rgb, width, height));
  SH_ASSIGN_OR_RETURN(const Halves halves, SplitOverlay(rgb, *width, *height));
  const ImageFeatures* features[2] = {&pipeline.left_features(), &pipeline.right_features()};
  // Corners that stereo paired into at least one 3-D point.
  std::vector<uint8_t> paired[2] = {std::vector<uint8_t>(features[0]->corners.size(), 0),
                                    std::vector<uint8_t>(features[1]->corners.size(), 0)};
  for (const ScenePoint& p : pipeline.scene().points) {
    if (p.source.left < paired[0].size()) paired[0][p.source.left] = 1;
    if (p.source.right < paired[1].size()) paired[1][p.source.right] = 1;
  }
  for (int v = 0; v < 2; ++v) {
    const ImageView<Rgb8>& image = halves.half[v];
    const EdgeMapView& edges = features[v]->edges;
    for (int y = 0; y < image.height; ++y) {
      for (int x = 0; x < image.width; ++x) {
        if (edges.edge.row(y)[x] != 0) image.at(x, y) = {40, 90, 255};
      }
    }
    for (const Line2D& line : features[v]->lines) {
      for (const Segment2D& seg : line.segments) {
        DrawSegment(image, seg.x0, seg.y0, seg.x1, seg.y1, {255, 230, 40});
      }
    }
    for (size_t i = 0; i < features[v]->corners.size(); ++i) {
      const Corner2D& c = features[v]->corners[i];
      const Rgb8 colour = paired[v][i] ? Rgb8{40, 255, 40} : Rgb8{255, 40, 40};
      const float x = c.x_px, y = c.y_px;
      DrawSegment(image, x - 3, y, x + 3, y, colour);
      DrawSegment(image, x, y - 3, x, y + 3, colour);
    }
  }
  return Status::Ok();
}

}  // namespace sh::tools
