#include "recog/shape/blob_split.hpp"

#include <algorithm>
#include <cstring>

namespace sh {
namespace {

constexpr uint32_t kUnset = 0xffffffffu;
constexpr uint32_t kMinCorePx = 30;  // a part must have grown this large to stay apart
constexpr uint16_t kFar = 0xfff0;

uint32_t Find(uint32_t* parent, uint32_t i) {
  uint32_t r = i;
  while (parent[r] != r) r = parent[r];
  while (parent[i] != r) {
    const uint32_t next = parent[i];
    parent[i] = r;
    i = next;
  }
  return r;
}

// Chamfer 3-4 distance transform of `d` in place: pixels at 0 are the sources, the others
// start at kFar; `outside` is the value beyond the box (0: the box border is a source).
void Chamfer(int w, int h, uint16_t outside, uint16_t* d) {
  auto at = [&](int x, int y) -> uint16_t {
    return (x < 0 || y < 0 || x >= w || y >= h) ? outside : d[static_cast<size_t>(y) * w + x];
  };
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      uint16_t& v = d[static_cast<size_t>(y) * w + x];
      if (v == 0) continue;
      v = std::min<uint16_t>(v, at(x - 1, y) + 3);
      v = std::min<uint16_t>(v, at(x, y - 1) + 3);
      v = std::min<uint16_t>(v, at(x - 1, y - 1) + 4);
      v = std::min<uint16_t>(v, at(x + 1, y - 1) + 4);
    }
  }
  for (int y = h - 1; y >= 0; --y) {
    for (int x = w - 1; x >= 0; --x) {
      uint16_t& v = d[static_cast<size_t>(y) * w + x];
      if (v == 0) continue;
      v = std::min<uint16_t>(v, at(x + 1, y) + 3);
      v = std::min<uint16_t>(v, at(x, y + 1) + 3);
      v = std::min<uint16_t>(v, at(x + 1, y + 1) + 4);
      v = std::min<uint16_t>(v, at(x - 1, y + 1) + 4);
    }
  }
}

// Chamfer 3-4 distance to the nearest outside pixel (pixels beyond the box are outside).
void Distance(ConstGrayView mask, uint16_t* d) {
  const int w = mask.width, h = mask.height;
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) d[static_cast<size_t>(y) * w + x] = mask.at(x, y) ? kFar : 0;
  }
  Chamfer(w, h, 0, d);
}

Status CheckSizes(ConstGrayView mask, int out_w, int out_h) {
  if (mask.empty() || out_w != mask.width || out_h != mask.height) {
    return Status::Error(StatusCode::kInvalidArgument, "mask parts: empty mask or output %dx%d",
                         out_w, out_h);
  }
  if (static_cast<size_t>(mask.width) * mask.height > kMaxSplitPixels) {
    return Status::Error(StatusCode::kOutOfRange, "mask parts: %dx%d exceeds %zu pixels",
                         mask.width, mask.height, kMaxSplitPixels);
  }
  return Status::Ok();
}

}  // namespace

Result<uint32_t> OpenMask(ConstGrayView mask, float ratio, MaskPartsScratch& s, GrayView out) {
  SH_RETURN_IF_ERROR(CheckSizes(mask, out.width, out.height));
  const int w = mask.width, h = mask.height;
  const size_t n = static_cast<size_t>(w) * h;
  Distance(mask, s.distance);
  uint16_t peak = 0;
  for (size_t i = 0; i < n; ++i) peak = std::max(peak, s.distance[i]);
  const float radius = ratio * peak;  // chamfer units (3 per pixel)
  // Distance from the core (pixels at least `radius` inside), over the whole box.
  uint16_t* e = s.peak;
  for (size_t i = 0; i < n; ++i) e[i] = s.distance[i] > 0 && s.distance[i] >= radius ? 0 : kFar;
  Chamfer(w, h, kFar, e);
  uint32_t kept = 0;
  for (int y = 0; y < h; ++y) {
    uint8_t* o = out.row(y);
    for (int x = 0; x < w; ++x) {
      const size_t i = static_cast<size_t>(y) * w + x;
      o[x] = mask.at(x, y) && e[i] <= radius ? 255 : 0;
      kept += o[x] != 0;
    }
  }
  return kept;
}

Result<int> MaskParts(ConstGrayView mask, bool split, float neck_ratio, int min_area,
                      MaskPartsScratch& s, GrayView labels, MaskPart* parts) {
  SH_RETURN_IF_ERROR(CheckSizes(mask, labels.width, labels.height));
  const int w = mask.width, h = mask.height;
  const size_t n = static_cast<size_t>(w) * h;
  if (split) {
    Distance(mask, s.distance);
  } else {
    for (int y = 0; y < h; ++y) {
      for (int x = 0; x < w; ++x)
        s.distance[static_cast<size_t>(y) * w + x] = mask.at(x, y) ? 1 : 0;
    }
  }
  // Inside pixels by decreasing distance (counting sort).
  uint16_t max_d = 0;
  for (size_t i = 0; i < n; ++i) max_d = std::max(max_d, s.distance[i]);
  if (max_d >= 3 * 1024) max_d = 3 * 1024;  // a 1024-pixel inscribed radius: beyond any box
  std::memset(s.count, 0, sizeof(uint32_t) * (max_d + 2u));
  for (size_t i = 0; i < n; ++i) {
    s.distance[i] = std::min(s.distance[i], max_d);
    if (s.distance[i] > 0) ++s.count[max_d - s.distance[i]];
  }
  uint32_t start = 0;
  for (int k = 0; k <= max_d; ++k) {
    const uint32_t c = s.count[k];
    s.count[k] = start;
    start += c;
  }
  const uint32_t inside = start;
  for (size_t i = 0; i < n; ++i) {
    if (s.distance[i] > 0) s.order[s.count[max_d - s.distance[i]]++] = static_cast<uint32_t>(i);
    s.parent[i] = kUnset;
  }
  // Grow parts from their peaks, keeping apart those that meet at a narrow neck.
  for (uint32_t k = 0; k < inside; ++k) {
    const uint32_t p = s.order[k];
    const int x = static_cast<int>(p % w), y = static_cast<int>(p / w);
    uint32_t roots[8];
    int n_roots = 0;
    for (int dy = -1; dy <= 1; ++dy) {
      for (int dx = -1; dx <= 1; ++dx) {
        const int xx = x + dx, yy = y + dy;
        if ((dx == 0 && dy == 0) || xx < 0 || yy < 0 || xx >= w || yy >= h) continue;
        const uint32_t q = static_cast<uint32_t>(yy) * w + xx;
        if (s.parent[q] == kUnset) continue;
        const uint32_t r = Find(s.parent, q);
        if (std::find(roots, roots + n_roots, r) == roots + n_roots) roots[n_roots++] = r;
      }
    }
    if (n_roots == 0) {
      s.parent[p] = p;
      s.area[p] = 1;
      s.peak[p] = s.distance[p];
      continue;
    }
    // Highest peak first (at most 8 roots: insertion sort).
    for (int i = 1; i < n_roots; ++i) {
      const uint32_t r = roots[i];
      int j = i;
      for (; j > 0 && s.peak[roots[j - 1]] < s.peak[r]; --j) roots[j] = roots[j - 1];
      roots[j] = r;
    }
    const uint32_t r0 = roots[0];
    for (int i = 1; i < n_roots; ++i) {
      const uint32_t r = Find(s.parent, roots[i]);
      const uint32_t base = Find(s.parent, r0);
      if (r == base) continue;
      const float smaller_peak = std::min(s.peak[r], s.peak[base]);
      const bool apart = split && s.distance[p] < neck_ratio * smaller_peak &&
                         s.area[r] >= kMinCorePx && s.area[base] >= kMinCorePx;
      if (apart) continue;
      s.parent[r] = base;
      s.area[base] += s.area[r];
      s.peak[base] = std::max(s.peak[base], s.peak[r]);
    }
    const uint32_t base = Find(s.parent, r0);
    s.parent[p] = base;
    ++s.area[base];
  }
  // Parts of at least min_area, the largest first when more than fit.
  uint32_t roots[kMaxMaskParts];
  int n_parts = 0;
  for (size_t i = 0; i < n; ++i) {
    if (s.parent[i] != i || s.area[i] < static_cast<uint32_t>(min_area)) continue;
    if (n_parts < kMaxMaskParts) {
      roots[n_parts++] = static_cast<uint32_t>(i);
    } else {
      int smallest = 0;
      for (int j = 1; j < n_parts; ++j) {
        if (s.area[roots[j]] < s.area[roots[smallest]]) smallest = j;
      }
      if (s.area[roots[smallest]] < s.area[i]) roots[smallest] = static_cast<uint32_t>(i);
    }
  }
  for (int j = 0; j < n_parts; ++j) {
    parts[j] = MaskPart{};
    parts[j].label = static_cast<uint8_t>(j + 1);
    parts[j].x0 = w;
    parts[j].y0 = h;
    parts[j].x1 = parts[j].y1 = -1;
  }
  double sx[kMaxMaskParts] = {}, sy[kMaxMaskParts] = {};
  for (int y = 0; y < h; ++y) {
    uint8_t* out = labels.row(y);
    for (int x = 0; x < w; ++x) {
      const size_t i = static_cast<size_t>(y) * w + x;
      out[x] = 0;
      if (s.parent[i] == kUnset) continue;
      const uint32_t r = Find(s.parent, static_cast<uint32_t>(i));
      const int j = static_cast<int>(std::find(roots, roots + n_parts, r) - roots);
      if (j == n_parts) continue;
      out[x] = parts[j].label;
      MaskPart& part = parts[j];
      ++part.area_px;
      part.x0 = std::min(part.x0, x);
      part.x1 = std::max(part.x1, x);
      part.y0 = std::min(part.y0, y);
      part.y1 = std::max(part.y1, y);
      sx[j] += x;
      sy[j] += y;
    }
  }
  for (int j = 0; j < n_parts; ++j) {
    parts[j].cx = static_cast<float>(sx[j] / parts[j].area_px);
    parts[j].cy = static_cast<float>(sy[j] / parts[j].area_px);
  }
  return n_parts;
}

}  // namespace sh
