#include "recog/image/hough.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>

#include "recog/base/angles.hpp"
#include "recog/image/gaussian.hpp"

namespace sh {

namespace {

// Votes are fixed point: a pixel exactly on a bin centre adds kVoteOne there. The rho position
// is quantised to 1/kSubBins bin to index the precomputed kernel weights (error <= 1/32 px,
// well inside the kernel width, and removed by the least-squares refinement).
constexpr int kVoteOne = 256;
constexpr int kSubBinBits = 4;
constexpr int kSubBins = 1 << kSubBinBits;
constexpr int kMaxTaps = 2 * kMaxVoteHalfWidthPx;
// Vote positions are computed in integers (sin and cos scaled by 2^kTrigBits): removing a pixel's
// votes then subtracts exactly what was added, whatever the compiler does with float arithmetic
// (contraction, vectorisation) in the two places. x sin + y cos + offset stays below 2^12 bins,
// so the scaled sums stay below 2^28.
constexpr int kTrigBits = 16;
constexpr int kPosShift = kTrigBits - kSubBinBits;  // scaled position -> 1/kSubBins bin
static_assert(kMaxImageWidth + kMaxImageHeight + kHoughRhoOffset < (1 << 12),
              "vote positions must fit in int32");

struct Tables {
  int32_t sin_q[kHoughThetaBins];  // sin(theta) * 2^kTrigBits, rounded
  int32_t cos_q[kHoughThetaBins];
  int16_t weight[kSubBins][kMaxTaps];    // bin (base - taps/2 + 1 + k) for sub-position s
  int taps = 0;                          // 2 * ceil(half width)
  int window = 0;                        // theta half-window in bins
  int32_t rho_offset = kHoughRhoOffset;  // the workspace's bin of rho 0
};

void BuildTables(const HoughConfig& config, Tables& tb) {
  for (int t = 0; t < kHoughThetaBins; ++t) {
    tb.sin_q[t] = static_cast<int32_t>(
        std::lround(std::sin(t * double{kHoughThetaStepRad}) * (1 << kTrigBits)));
    tb.cos_q[t] = static_cast<int32_t>(
        std::lround(std::cos(t * double{kHoughThetaStepRad}) * (1 << kTrigBits)));
  }
  const float hw = config.vote_half_width_px;
  const int half = static_cast<int>(std::ceil(hw));
  tb.taps = 2 * half;
  for (int s = 0; s < kSubBins; ++s) {
    for (int k = 0; k < kMaxTaps; ++k) {
      // Distance of bin (base - half + 1 + k) from the vote position base + s / kSubBins.
      const float d = static_cast<float>(k - half + 1) - static_cast<float>(s) / kSubBins;
      const float w = std::fabs(d) < hw ? std::cos(kPi * d / (2.0f * hw)) : 0.0f;
      tb.weight[s][k] = k < tb.taps ? static_cast<int16_t>(std::lround(w * kVoteOne)) : 0;
    }
  }
  tb.window =
      static_cast<int>(std::lround(config.angle_window_deg * kPi / 180.0f / kHoughThetaStepRad));
}

// The largest rho of a pixel of a width x height image, in whole bins.
int ImageDiagonal(int width, int height) {
  return static_cast<int>(std::ceil(std::hypot(width, height)));
}

int WrapTheta(int t) {
  t %= kHoughThetaBins;
  return t < 0 ? t + kHoughThetaBins : t;
}

// Theta bin of the line through a pixel whose gradient has the given edge-map orientation: the
// normal (sin theta, cos theta) is parallel to the gradient (cos phi, sin phi), so
// theta = pi/2 - phi (mod pi). In bins: 180 - orientation * 360 / 256.
int16_t CentreThetaBin(uint8_t orientation) {
  const int t = static_cast<int>(
      std::lround(kHoughThetaBins / 2.0 - orientation * (kHoughThetaBins / 256.0)));
  return static_cast<int16_t>(WrapTheta(t));
}

// Adds (kSign +1) or removes (kSign -1) the votes of the points points[begin, end) (kIndexed:
// points[idx[begin, end)]) in accumulator row t, and with kMarkDirty marks the blocks touched.
// The vote position is x sin + y cos + offset in 1/kSubBins bins (rounded); the kernel's taps
// start half - 1 bins below its bin. Template arguments keep the loop free of the choices and
// let the tap loop unroll.
template <int kSign, int kTaps, bool kIndexed, bool kMarkDirty>
void VoteRowT(int32_t* __restrict row, uint8_t* __restrict dirty, const Tables& tb, int t,
              const HoughEdgePoint* points, const uint32_t* idx, int32_t begin, int32_t end) {
  const int32_t s = tb.sin_q[t], c = tb.cos_q[t];
  const int32_t off = (tb.rho_offset << kTrigBits) + (1 << (kPosShift - 1));
  constexpr int kFirst = 1 - kTaps / 2;  // first tap relative to the vote's bin
  for (int32_t i = begin; i < end; ++i) {
    const HoughEdgePoint& p = points[kIndexed ? idx[i] : static_cast<uint32_t>(i)];
    const int32_t q = (p.x * s + p.y * c + off) >> kPosShift;
    const int32_t first = (q >> kSubBinBits) + kFirst;
    int32_t* cell = row + first;
    const int16_t* w = tb.weight[q & (kSubBins - 1)];
    for (int k = 0; k < kTaps; ++k) cell[k] += kSign * w[k];
    if (kMarkDirty) {
      dirty[first / HoughWorkspace::kBlock] = 1;
      dirty[(first + kTaps - 1) / HoughWorkspace::kBlock] = 1;
    }
  }
}

// Casting (all points of a range) and removal (listed points, marking dirty blocks).
template <int kSign, bool kIndexed, bool kMarkDirty>
void VoteRow(int32_t* row, uint8_t* dirty, const Tables& tb, int t, const HoughEdgePoint* points,
             const uint32_t* idx, int32_t begin, int32_t end) {
  switch (tb.taps) {
    case 2:
      VoteRowT<kSign, 2, kIndexed, kMarkDirty>(row, dirty, tb, t, points, idx, begin, end);
      break;
    case 4:
      VoteRowT<kSign, 4, kIndexed, kMarkDirty>(row, dirty, tb, t, points, idx, begin, end);
      break;
    case 6:
      VoteRowT<kSign, 6, kIndexed, kMarkDirty>(row, dirty, tb, t, points, idx, begin, end);
      break;
    default:
      VoteRowT<kSign, kMaxTaps, kIndexed, kMarkDirty>(row, dirty, tb, t, points, idx, begin, end);
      break;
  }
}

// Maximum of one block and its first position (a branch-free reduction the compiler
// vectorises, then the first cell holding it: the same cell as a scan that keeps the earliest of
// equal maxima).
void BlockMax(HoughWorkspace& ws, int t, int b) {
  const int32_t* cell = ws.AccRow(t) + static_cast<ptrdiff_t>(b) * HoughWorkspace::kBlock;
  int32_t m = cell[0];
  for (int i = 1; i < HoughWorkspace::kBlock; ++i) m = cell[i] > m ? cell[i] : m;
  int arg = 0;
  while (cell[arg] != m) ++arg;
  ws.block_max[t][b] = m;
  ws.block_arg[t][b] = static_cast<int16_t>(b * HoughWorkspace::kBlock + arg);
}

// Row maximum from the block maxima; recomputes the dirty blocks first.
void RowMax(HoughWorkspace& ws, int t, int block_lo, int block_hi) {
  int32_t best = INT32_MIN;
  int16_t best_arg = 0;
  for (int b = block_lo; b <= block_hi; ++b) {
    if (ws.block_dirty[t][b]) {
      ws.block_dirty[t][b] = 0;
      BlockMax(ws, t, b);
    }
    if (ws.block_max[t][b] > best) {
      best = ws.block_max[t][b];
      best_arg = ws.block_arg[t][b];
    }
  }
  ws.row_max[t] = best;
  ws.row_arg[t] = best_arg;
  ws.row_dirty[t] = 0;
}

// Only blocks [block_lo, block_hi] can hold votes for the current image size.
void UpdateMaxima(HoughWorkspace& ws, int block_lo, int block_hi) {
  for (int t = 0; t < kHoughThetaBins; ++t) {
    if (ws.row_dirty[t]) RowMax(ws, t, block_lo, block_hi);
  }
}

// The whole transform, one accumulator row at a time: row t is cleared, receives the votes of
// every pixel whose theta window holds t (the points are sorted by window centre, so these are
// 2 window + 1 contiguous ranges), and gets its maxima while it is still in cache. Casting the
// votes pixel by pixel instead scatters each pixel's votes over 2 window + 1 rows of several KiB,
// a cache miss per row.
void CastAllVotes(HoughWorkspace& ws, const Tables& tb, int block_lo, int block_hi) {
  for (int t = 0; t < kHoughThetaBins; ++t) {
    int32_t* row = ws.AccRow(t);
    std::fill(row + ws.acc_lo, row + ws.acc_hi, 0);
    for (int j = -tb.window; j <= tb.window; ++j) {
      const int tc = WrapTheta(t - j);
      VoteRow<+1, false, false>(row, nullptr, tb, t, ws.points, nullptr, ws.theta_start[tc],
                                ws.theta_start[tc + 1]);
    }
    for (int b = block_lo; b <= block_hi; ++b) ws.block_dirty[t][b] = 1;
    RowMax(ws, t, block_lo, block_hi);
  }
}

// Removes the votes of the points ws.points[idx[0..n)] and marks the touched blocks and rows for
// a new maximum. CollectPoints gathers the points grouped by window centre; each group's rows are
// done together (the next group's rows are mostly the same ones, still in cache).
void RemoveVotes(HoughWorkspace& ws, const Tables& tb, const uint32_t* idx, size_t n) {
  size_t i = 0;
  while (i < n) {
    const int tc = ws.points[idx[i]].tc;
    size_t e = i + 1;
    while (e < n && ws.points[idx[e]].tc == tc) ++e;
    for (int j = -tb.window; j <= tb.window; ++j) {
      const int t = WrapTheta(tc + j);
      VoteRow<-1, true, true>(ws.AccRow(t), ws.block_dirty[t], tb, t, ws.points, idx,
                              static_cast<int32_t>(i), static_cast<int32_t>(e));
      ws.row_dirty[t] = 1;
    }
    i = e;
  }
}

// Accumulator value with theta wrapping: theta - pi has the opposite rho.
float AccAt(const HoughWorkspace& ws, int t, int r) {
  if (t < 0 || t >= kHoughThetaBins) {
    t = WrapTheta(t);
    r = 2 * ws.rho_offset - r;  // bin of -rho
  }
  if (r < ws.acc_lo || r >= ws.acc_hi) return 0.0f;
  return static_cast<float>(ws.AccRow(t)[r]);
}

// Quadratic least-squares fit over the 3x3 neighbourhood (Niblack & Petkovic); returns false if
// the fit has no maximum within max_shift bins.
bool InterpolatePeak(const HoughWorkspace& ws, int t, int r, float max_shift, float& dt,
                     float& dr) {
  float f[3][3];
  for (int i = -1; i <= 1; ++i) {
    for (int j = -1; j <= 1; ++j) f[i + 1][j + 1] = AccAt(ws, t + i, r + j);
  }
  float bt = 0, br = 0, ctt = 0, crr = 0, ctr = 0;
  for (int i = -1; i <= 1; ++i) {
    for (int j = -1; j <= 1; ++j) {
      const float v = f[i + 1][j + 1];
      bt += i * v / 6.0f;
      br += j * v / 6.0f;
      ctt += (i * i - 2.0f / 3.0f) * v / 2.0f;
      crr += (j * j - 2.0f / 3.0f) * v / 2.0f;
      ctr += i * j * v / 4.0f;
    }
  }
  // Stationary point of c + bt t + br r + ctt t^2 + crr r^2 + ctr t r.
  const float a = 2.0f * ctt, b = ctr, d = 2.0f * crr;
  const float det = a * d - b * b;
  if (!(a < 0.0f && det > 0.0f)) return false;
  dt = -(d * bt - b * br) / det;
  dr = -(a * br - b * bt) / det;
  return std::fabs(dt) <= max_shift && std::fabs(dr) <= max_shift;
}

void NormaliseLine(float& theta, float& rho) {
  while (theta < 0.0f) {
    theta += kPi;
    rho = -rho;
  }
  while (theta >= kPi) {
    theta -= kPi;
    rho = -rho;
  }
}

// Total least squares over the given points; returns false for fewer than two distinct points.
bool FitLine(const HoughWorkspace& ws, const uint32_t* idx, size_t n, float& theta, float& rho) {
  if (n < 2) return false;
  double sx = 0, sy = 0;
  for (size_t i = 0; i < n; ++i) {
    sx += ws.points[idx[i]].x;
    sy += ws.points[idx[i]].y;
  }
  const double mx = sx / n, my = sy / n;
  double cxx = 0, cxy = 0, cyy = 0;
  for (size_t i = 0; i < n; ++i) {
    const double dx = ws.points[idx[i]].x - mx, dy = ws.points[idx[i]].y - my;
    cxx += dx * dx;
    cxy += dx * dy;
    cyy += dy * dy;
  }
  if (cxx + cyy <= 0.0) return false;
  // Direction of largest spread; the normal is perpendicular to it.
  const double phi = 0.5 * std::atan2(2.0 * cxy, cxx - cyy);
  const double nx = -std::sin(phi), ny = std::cos(phi);  // normal = (sin theta, cos theta)
  double th = std::atan2(nx, ny);
  double rh = nx * mx + ny * my;
  float t = static_cast<float>(th), r = static_cast<float>(rh);
  NormaliseLine(t, r);
  theta = t;
  rho = r;
  return true;
}

void FillLineGeometry(float theta, float rho, Line2D& line) {
  line.theta_rad = theta;
  line.rho_px = rho;
  const float s = std::sin(theta), c = std::cos(theta);
  line.dir_x = c;
  line.dir_y = -s;
  line.point_x_px = rho * s;
  line.point_y_px = rho * c;
}

// Runs of the given pixels (those within max_dist of the line) along the line: 1 px bins of
// the position t along the direction, merged across gaps of at most max_gap_px. Returns the
// number of runs in ws.runs, ordered along the line.
size_t BuildRuns(HoughWorkspace& ws, const Line2D& line, const uint32_t* idx, size_t n,
                 float max_dist, float max_gap_px) {
  constexpr int kOffset = HoughWorkspace::kSupportBins / 2;
  int lo_bin = HoughWorkspace::kSupportBins, hi_bin = -1;
  for (size_t i = 0; i < n; ++i) {
    const HoughEdgePoint& p = ws.points[idx[i]];
    if (std::fabs(line.DistancePx(p.x, p.y)) > max_dist) continue;
    const float t = (p.x - line.point_x_px) * line.dir_x + (p.y - line.point_y_px) * line.dir_y;
    const int b =
        std::clamp(static_cast<int>(std::floor(t)) + kOffset, 0, HoughWorkspace::kSupportBins - 1);
    if (b < lo_bin || b > hi_bin) {
      // Newly touched range: initialise the bins outside the old extent.
      const int from = hi_bin < 0 ? b : std::min(b, lo_bin);
      const int to = hi_bin < 0 ? b : std::max(b, hi_bin);
      for (int k = from; k <= to; ++k) {
        if (hi_bin < 0 || k < lo_bin || k > hi_bin) {
          ws.support_lo[k] = INFINITY;
          ws.support_hi[k] = -INFINITY;
          ws.support_count[k] = 0;
        }
      }
      lo_bin = from;
      hi_bin = to;
    }
    ws.support_lo[b] = std::min(ws.support_lo[b], t);
    ws.support_hi[b] = std::max(ws.support_hi[b], t);
    ++ws.support_count[b];
  }
  size_t run_count = 0;
  bool open = false;
  HoughWorkspace::Run cur{};
  for (int k = lo_bin; k <= hi_bin; ++k) {
    if (ws.support_count[k] == 0) continue;
    // Gap = missing length between the pixel extents (each pixel covers +-0.5 px).
    if (open && ws.support_lo[k] - cur.t1 - 1.0f <= max_gap_px) {
      cur.t1 = ws.support_hi[k];
      cur.count += ws.support_count[k];
    } else {
      if (open) ws.runs[run_count++] = cur;
      cur = HoughWorkspace::Run{};
      cur.t0 = ws.support_lo[k];
      cur.t1 = ws.support_hi[k];
      cur.count = ws.support_count[k];
      open = true;
    }
  }
  if (open) ws.runs[run_count++] = cur;
  return run_count;
}

// Segments of the line covered by the given pixels within support_distance_px.
void ComputeSupport(HoughWorkspace& ws, const HoughConfig& config, const uint32_t* idx, size_t n,
                    Line2D& line) {
  const size_t run_count =
      BuildRuns(ws, line, idx, n, config.support_distance_px, config.max_gap_px);
  line.segments.clear();
  line.support_length_px = 0.0f;
  size_t kept = 0;
  for (size_t i = 0; i < run_count; ++i) {
    HoughWorkspace::Run r = ws.runs[i];
    r.t0 -= 0.5f;
    r.t1 += 0.5f;
    if (r.t1 - r.t0 < config.min_segment_px) continue;
    line.support_length_px += r.t1 - r.t0;
    ws.runs[kept++] = r;
  }
  if (kept > kMaxSegmentsPerLine) {
    // Keep the longest, then restore the order along the line.
    std::nth_element(ws.runs, ws.runs + kMaxSegmentsPerLine - 1, ws.runs + kept,
                     [](const HoughWorkspace::Run& a, const HoughWorkspace::Run& b) {
                       return a.t1 - a.t0 > b.t1 - b.t0;
                     });
    kept = kMaxSegmentsPerLine;
    std::sort(
        ws.runs, ws.runs + kept,
        [](const HoughWorkspace::Run& a, const HoughWorkspace::Run& b) { return a.t0 < b.t0; });
  }
  for (size_t i = 0; i < kept; ++i) {
    const HoughWorkspace::Run& r = ws.runs[i];
    Segment2D s;
    s.x0 = line.point_x_px + r.t0 * line.dir_x;
    s.y0 = line.point_y_px + r.t0 * line.dir_y;
    s.x1 = line.point_x_px + r.t1 * line.dir_x;
    s.y1 = line.point_y_px + r.t1 * line.dir_y;
    (void)line.segments.push_back(s);  // kept <= capacity
  }
}

// Pixels of idx[0..n) within max_dist of the line, into ws.subset; returns their count.
size_t SelectNear(HoughWorkspace& ws, const Line2D& line, const uint32_t* idx, size_t n,
                  float max_dist) {
  size_t m = 0;
  for (size_t i = 0; i < n; ++i) {
    const HoughEdgePoint& p = ws.points[idx[i]];
    if (std::fabs(line.DistancePx(p.x, p.y)) <= max_dist) ws.subset[m++] = idx[i];
  }
  return m;
}

// Least-squares line of the collected pixels, robust to a peak that bridges nearly collinear
// edges: fit all, take the run with most pixels along that fit as the seed, fit it, then refit
// with the pixels within support_distance_px (twice). theta/rho are updated when a fit succeeds.
void RobustFit(HoughWorkspace& ws, const HoughConfig& config, size_t n, float& theta, float& rho) {
  float t = theta, r = rho;
  if (!FitLine(ws, ws.collected, n, t, r)) return;
  Line2D line;
  FillLineGeometry(t, r, line);
  const size_t run_count =
      BuildRuns(ws, line, ws.collected, n, config.collect_distance_px, config.max_gap_px);
  if (run_count > 1) {
    size_t best = 0;
    for (size_t i = 1; i < run_count; ++i) {
      if (ws.runs[i].count > ws.runs[best].count) best = i;
    }
    const HoughWorkspace::Run seed = ws.runs[best];
    size_t m = 0;
    for (size_t i = 0; i < n; ++i) {
      const HoughEdgePoint& p = ws.points[ws.collected[i]];
      const float pt = (p.x - line.point_x_px) * line.dir_x + (p.y - line.point_y_px) * line.dir_y;
      if (pt >= seed.t0 && pt <= seed.t1) ws.subset[m++] = ws.collected[i];
    }
    float t2 = t, r2 = r;
    if (FitLine(ws, ws.subset, m, t2, r2)) {
      t = t2;
      r = r2;
      FillLineGeometry(t, r, line);
    }
  }
  for (int iter = 0; iter < 2; ++iter) {
    const size_t m = SelectNear(ws, line, ws.collected, n, config.support_distance_px);
    float t2 = t, r2 = r;
    if (!FitLine(ws, ws.subset, m, t2, r2)) break;
    t = t2;
    r = r2;
    FillLineGeometry(t, r, line);
  }
  theta = t;
  rho = r;
}

// Drops from ws.collected[0..n) the runs whose own direction deviates from the line by more than
// max_run_angle_deg (edges crossing at a shallow angle). Returns the new count; keeps everything
// if that would leave nothing.
size_t ReleaseCrossingRuns(HoughWorkspace& ws, const HoughConfig& config, const Line2D& line,
                           size_t n) {
  const size_t run_count =
      BuildRuns(ws, line, ws.collected, n, config.collect_distance_px, config.max_gap_px);
  if (run_count < 2) return n;
  auto run_of = [&](float t) {
    // Runs are ordered along the line; the last run starting at or before t holds it.
    size_t lo = 0, hi = run_count;
    while (hi - lo > 1) {
      const size_t mid = (lo + hi) / 2;
      (ws.runs[mid].t0 <= t ? lo : hi) = mid;
    }
    return lo;
  };
  for (size_t i = 0; i < n; ++i) {
    const HoughEdgePoint& p = ws.points[ws.collected[i]];
    const float dx = p.x - line.point_x_px, dy = p.y - line.point_y_px;
    HoughWorkspace::Run& r = ws.runs[run_of(dx * line.dir_x + dy * line.dir_y)];
    r.sx += dx;
    r.sy += dy;
    r.sxx += dx * dx;
    r.sxy += dx * dy;
    r.syy += dy * dy;
  }
  const float max_angle = config.max_run_angle_deg * kPi / 180.0f;
  const float line_angle = std::atan2(line.dir_y, line.dir_x);
  bool any_kept = false;
  for (size_t k = 0; k < run_count; ++k) {
    HoughWorkspace::Run& r = ws.runs[k];
    r.keep = true;
    if (r.count < 6) {
      any_kept = true;
      continue;
    }
    const float c = static_cast<float>(r.count);
    const float cxx = r.sxx - r.sx * r.sx / c, cxy = r.sxy - r.sx * r.sy / c;
    const float cyy = r.syy - r.sy * r.sy / c;
    const float run_angle = 0.5f * std::atan2(2.0f * cxy, cxx - cyy);
    float diff = std::fabs(std::remainder(run_angle - line_angle, kPi));
    r.keep = diff <= max_angle;
    any_kept = any_kept || r.keep;
  }
  if (!any_kept) return n;
  size_t m = 0;
  for (size_t i = 0; i < n; ++i) {
    const HoughEdgePoint& p = ws.points[ws.collected[i]];
    const float t = (p.x - line.point_x_px) * line.dir_x + (p.y - line.point_y_px) * line.dir_y;
    if (ws.runs[run_of(t)].keep) ws.collected[m++] = ws.collected[i];
  }
  return m;
}

// Gathers the pixel list from the edge map, sorted by theta window centre (counting sort). One
// scan of the edge map: the pixels go to ws.collected first (as y * width + x, with their centre
// in ws.subset), then into their places. Edge maps are sparse, so the scan skips eight zero
// bytes at a time.
void GatherPoints(const ConstEdgeMapView& edges, HoughWorkspace& ws, size_t& dropped) {
  int32_t count[kHoughThetaBins] = {};
  size_t total = 0;
  dropped = 0;
  const int w = edges.edge.width, h = edges.edge.height;
  for (int y = 0; y < h; ++y) {
    const uint8_t* e = edges.edge.row(y);
    const uint8_t* o = edges.orientation.row(y);
    int x = 0;
    while (x < w) {
      if (x + 8 <= w) {
        uint64_t word;
        std::memcpy(&word, e + x, sizeof word);
        if (word == 0) {
          x += 8;
          continue;
        }
      }
      const int end = std::min(w, x + 8);
      for (; x < end; ++x) {
        if (e[x] == 0) continue;
        if (total == ws.point_capacity()) {
          ++dropped;
          continue;
        }
        const int16_t tc = CentreThetaBin(o[x]);
        ws.collected[total] = static_cast<uint32_t>(y) * static_cast<uint32_t>(w) + x;
        ws.subset[total] = static_cast<uint32_t>(tc);
        ++total;
        ++count[tc];
      }
    }
  }
  ws.theta_start[0] = 0;
  for (int t = 0; t < kHoughThetaBins; ++t) ws.theta_start[t + 1] = ws.theta_start[t] + count[t];
  int32_t fill[kHoughThetaBins];
  std::copy(ws.theta_start, ws.theta_start + kHoughThetaBins, fill);
  for (size_t i = 0; i < total; ++i) {
    const int16_t tc = static_cast<int16_t>(ws.subset[i]);
    HoughEdgePoint& p = ws.points[fill[tc]++];
    p.x = static_cast<int16_t>(ws.collected[i] % static_cast<uint32_t>(w));
    p.y = static_cast<int16_t>(ws.collected[i] / static_cast<uint32_t>(w));
    p.tc = tc;
    p.line = -1;
  }
  ws.point_count = total;
}

// Unassigned pixels within collect_distance_px of the line whose theta window holds bin t.
size_t CollectPoints(HoughWorkspace& ws, const Tables& tb, int t, float theta, float rho,
                     float distance) {
  const float s = std::sin(theta), c = std::cos(theta);
  size_t n = 0;
  for (int j = -tb.window; j <= tb.window; ++j) {
    const int tc = WrapTheta(t + j);
    for (int32_t i = ws.theta_start[tc]; i < ws.theta_start[tc + 1]; ++i) {
      const HoughEdgePoint& p = ws.points[i];
      if (p.line != -1) continue;
      if (std::fabs(p.x * s + p.y * c - rho) <= distance)
        ws.collected[n++] = static_cast<uint32_t>(i);
    }
  }
  return n;
}

}  // namespace

Status ValidateHoughConfig(const HoughConfig& config) {
  if (!(config.angle_window_deg >= 0.0f && config.angle_window_deg <= 45.0f)) {
    return Status::Error(StatusCode::kOutOfRange, "Hough angle window %g deg outside [0, 45]",
                         static_cast<double>(config.angle_window_deg));
  }
  if (!(config.vote_half_width_px >= 0.5f &&
        config.vote_half_width_px <= static_cast<float>(kMaxVoteHalfWidthPx))) {
    return Status::Error(StatusCode::kOutOfRange, "Hough vote half width %g px outside [0.5, %d]",
                         static_cast<double>(config.vote_half_width_px), kMaxVoteHalfWidthPx);
  }
  if (!(config.min_votes >= 1.0f) || config.min_edge_pixels < 2 || config.max_peaks < 1) {
    return Status::Error(StatusCode::kInvalidArgument,
                         "Hough needs min_votes >= 1, min_edge_pixels >= 2, max_peaks >= 1");
  }
  if (!(config.collect_distance_px > 0.0f) || !(config.support_distance_px > 0.0f) ||
      !(config.max_gap_px >= 0.0f) || !(config.min_segment_px >= 0.0f) ||
      !(config.max_refine_shift_bins >= 0.0f) || !(config.max_run_angle_deg > 0.0f)) {
    return Status::Error(StatusCode::kInvalidArgument,
                         "Hough distances must be positive (collect %g, support %g px)",
                         static_cast<double>(config.collect_distance_px),
                         static_cast<double>(config.support_distance_px));
  }
  return Status::Ok();
}

int HoughWorkspace::RhoOffsetFor(int height) {
  return kHoughRhoOffset - kBlock * ((kHoughRhoOffset - height - kMaxVoteHalfWidthPx) / kBlock);
}

int HoughWorkspace::AccStrideFor(int width, int height) {
  const int block_hi =
      (RhoOffsetFor(height) + ImageDiagonal(width, height) + kMaxVoteHalfWidthPx) / kBlock;
  return (block_hi + 1) * kBlock;
}

size_t HoughWorkspace::OwnBytesFor(int width, int height) {
  return InitBlock::PieceBytes<int32_t>(size_t{kHoughThetaBins} *
                                        static_cast<size_t>(AccStrideFor(width, height))) +
         InitBlock::PieceBytes<HoughEdgePoint>(HoughEdgeCapacity(width, height));
}

size_t HoughWorkspace::ScratchBytesFor(int width, int height) {
  return 2 * InitBlock::PieceBytes<uint32_t>(HoughEdgeCapacity(width, height));
}

size_t HoughWorkspace::BytesFor(int width, int height) {
  return OwnBytesFor(width, height) + ScratchBytesFor(width, height);
}

void HoughWorkspace::TakeOwn(int width, int height) {
  rho_offset = RhoOffsetFor(height);
  acc_stride = AccStrideFor(width, height);
  acc_lo = acc_hi = 0;
  acc = block_.Take<int32_t>(size_t{kHoughThetaBins} * static_cast<size_t>(acc_stride));
  points = block_.Take<HoughEdgePoint>(HoughEdgeCapacity(width, height));
}

Status HoughWorkspace::Init(int width, int height) {
  if (block_.Holds(width, height) && borrowed_ == nullptr) return Status::Ok();
  point_capacity_ = 0;
  borrowed_ = nullptr;
  SH_RETURN_IF_ERROR(block_.Allocate(width, height, BytesFor(width, height), "Hough workspace"));
  const size_t n = HoughEdgeCapacity(width, height);
  TakeOwn(width, height);
  collected = block_.Take<uint32_t>(n);
  subset = block_.Take<uint32_t>(n);
  point_capacity_ = n;
  return Status::Ok();
}

Status HoughWorkspace::Init(int width, int height, uint8_t* scratch, size_t scratch_bytes) {
  if (scratch == nullptr || scratch_bytes < ScratchBytesFor(width, height)) {
    return Status::Error(StatusCode::kInvalidArgument,
                         "Hough workspace: %zu bytes of scratch for %dx%d, %zu needed",
                         scratch == nullptr ? size_t{0} : scratch_bytes, width, height,
                         ScratchBytesFor(width, height));
  }
  const size_t n = HoughEdgeCapacity(width, height);
  if (!block_.Holds(width, height) || borrowed_ == nullptr) {
    point_capacity_ = 0;
    borrowed_ = nullptr;
    SH_RETURN_IF_ERROR(
        block_.Allocate(width, height, OwnBytesFor(width, height), "Hough workspace"));
    TakeOwn(width, height);
  }
  // Two pieces aligned as InitBlock aligns them (ScratchBytesFor holds the slack).
  const auto align = [](uint8_t* p) {
    const uintptr_t at = reinterpret_cast<uintptr_t>(p);
    return p + (InitBlock::kAlign - at % InitBlock::kAlign) % InitBlock::kAlign;
  };
  uint8_t* const first = align(scratch);
  collected = reinterpret_cast<uint32_t*>(first);
  subset = reinterpret_cast<uint32_t*>(align(first + n * sizeof(uint32_t)));
  borrowed_ = scratch;
  point_capacity_ = n;
  return Status::Ok();
}

Status DetectLines(const ConstEdgeMapView& edges, const HoughConfig& config, HoughWorkspace& ws,
                   Vector<Line2D>& lines, HoughStats* stats) {
  lines.clear();
  HoughStats st;
  if (stats != nullptr) *stats = st;
  const ImageView<const uint8_t>& e = edges.edge;
  const ImageView<const uint8_t>& o = edges.orientation;
  if (e.data == nullptr || o.data == nullptr || e.width <= 0 || e.height <= 0) {
    return Status::Error(StatusCode::kInvalidArgument, "DetectLines: empty edge map (%dx%d)",
                         e.width, e.height);
  }
  if (o.width != e.width || o.height != e.height || e.stride < e.width || o.stride < o.width) {
    return Status::Error(StatusCode::kInvalidArgument,
                         "DetectLines: edge %dx%d and orientation %dx%d planes do not match",
                         e.width, e.height, o.width, o.height);
  }
  if (e.width > kMaxImageWidth || e.height > kMaxImageHeight) {
    return Status::Error(StatusCode::kOutOfRange, "DetectLines: edge map %dx%d larger than %dx%d",
                         e.width, e.height, kMaxImageWidth, kMaxImageHeight);
  }
  SH_RETURN_IF_ERROR(ValidateHoughConfig(config));
  SH_RETURN_IF_ERROR(CheckFitsWorkspace(e.width, e.height, ws.block(), "DetectLines (workspace)"));
  Tables tb;
  BuildTables(config, tb);
  tb.rho_offset = ws.rho_offset;

  GatherPoints(edges, ws, st.edge_pixels_dropped);
  st.edge_pixels = ws.point_count;
  // Votes of this image land in rho bins rho_offset + [-(height - 1), diagonal], widened by the
  // kernel; only those blocks are cleared and searched (within the accumulator: the image fits
  // the workspace).
  const int diagonal = ImageDiagonal(e.width, e.height);
  const int block_lo = (ws.rho_offset - e.height - kMaxVoteHalfWidthPx) / HoughWorkspace::kBlock;
  const int block_hi = (ws.rho_offset + diagonal + kMaxVoteHalfWidthPx) / HoughWorkspace::kBlock;
  ws.acc_lo = block_lo * HoughWorkspace::kBlock;
  ws.acc_hi = (block_hi + 1) * HoughWorkspace::kBlock;
  CastAllVotes(ws, tb, block_lo, block_hi);

  const int32_t min_acc = static_cast<int32_t>(std::ceil(config.min_votes * kVoteOne));
  while (true) {
    if (st.peaks_examined >= static_cast<size_t>(config.max_peaks) || lines.full()) {
      st.stopped_by_capacity = true;
      break;
    }
    UpdateMaxima(ws, block_lo, block_hi);
    int best_t = 0;
    for (int t = 1; t < kHoughThetaBins; ++t) {
      if (ws.row_max[t] > ws.row_max[best_t]) best_t = t;
    }
    const int32_t peak = ws.row_max[best_t];
    if (peak < min_acc) break;
    ++st.peaks_examined;
    const int best_r = ws.row_arg[best_t];
    float dt = 0.0f, dr = 0.0f;
    if (InterpolatePeak(ws, best_t, best_r, config.max_refine_shift_bins, dt, dr)) {
      ++st.peaks_refined;
    } else {
      dt = dr = 0.0f;
    }
    float theta = (best_t + dt) * kHoughThetaStepRad;
    float rho = static_cast<float>(best_r - ws.rho_offset) + dr;
    NormaliseLine(theta, rho);
    size_t n = CollectPoints(ws, tb, best_t, theta, rho, config.collect_distance_px);
    if (n == 0) {
      // Cannot happen while every vote comes from an unassigned pixel within the kernel width,
      // but guarantees progress: retire the cell.
      ws.AccRow(best_t)[best_r] = 0;
      ws.row_dirty[best_t] = 1;
      ws.block_dirty[best_t][best_r / HoughWorkspace::kBlock] = 1;
      ++st.lines_rejected;
      continue;
    }
    // Fit, then take the line's pixels afresh around the fitted line (in its own theta window):
    // pixels of a different edge that the peak's band picked up stay for their own line.
    float fit_theta = theta, fit_rho = rho;
    RobustFit(ws, config, n, fit_theta, fit_rho);
    const int fit_t = WrapTheta(static_cast<int>(std::lround(fit_theta / kHoughThetaStepRad)));
    size_t m = CollectPoints(ws, tb, fit_t, fit_theta, fit_rho, config.collect_distance_px);
    if (m == 0) m = CollectPoints(ws, tb, best_t, theta, rho, config.collect_distance_px);
    {
      Line2D fitted;
      FillLineGeometry(fit_theta, fit_rho, fitted);
      m = ReleaseCrossingRuns(ws, config, fitted, m);
    }
    n = m;
    RemoveVotes(ws, tb, ws.collected, n);

    Line2D line;
    line.votes = static_cast<float>(peak) / kVoteOne;
    FillLineGeometry(fit_theta, fit_rho, line);
    // Final fit on the pixels within the support distance of the assigned set.
    const size_t close = SelectNear(ws, line, ws.collected, n, config.support_distance_px);
    if (FitLine(ws, ws.subset, close, fit_theta, fit_rho))
      FillLineGeometry(fit_theta, fit_rho, line);
    ComputeSupport(ws, config, ws.collected, n, line);
    const size_t supporting = SelectNear(ws, line, ws.collected, n, config.support_distance_px);
    const bool accept =
        supporting >= static_cast<size_t>(config.min_edge_pixels) && !line.segments.empty();
    const int16_t owner = accept ? static_cast<int16_t>(lines.size()) : int16_t{-2};
    for (size_t i = 0; i < n; ++i) ws.points[ws.collected[i]].line = owner;
    st.edge_pixels_assigned += n;
    if (!accept) {
      ++st.lines_rejected;
      continue;
    }
    line.edge_pixels = static_cast<int>(n);
    (void)lines.push_back(line);  // not full: checked at the top of the loop
  }
  if (stats != nullptr) *stats = st;
  return Status::Ok();
}

}  // namespace sh
