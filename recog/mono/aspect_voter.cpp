#include "recog/mono/aspect_voter.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>

#include "recog/base/angles.hpp"

namespace sh {
namespace {

// Q4.12 hash coordinate -> hash units.
constexpr float kHashUnit = 1.0f / static_cast<float>(1 << 12);
// Q2.14 unit-vector component -> float.
constexpr float kUnitScale = 1.0f / static_cast<float>(1 << 14);
// x = d^2 / sigma^2 -> the vote table's fine index (UQ8.8 plus the interpolation bits).
constexpr float kVoteIndexScale =
    static_cast<float>(1u << (kVoteIndexFractionBits + VoteTable::kInterpolationBits));
// A vote in UQ0.16 raw units -> [0, 1).
constexpr float kVoteScale = 1.0f / 65536.0f;

// Bin range [lo, hi] of the interval [value - reach, value + reach] on one axis, clipped;
// false when the interval misses the grid.
bool BinRange(float value, float reach, float min, float bin, int dims, int* lo, int* hi) {
  const float a = (value - reach - min) / bin, b = (value + reach - min) / bin;
  if (!(b >= 0.0f) || !(a < static_cast<float>(dims))) return false;
  *lo = std::max(0, static_cast<int>(std::floor(a)));
  *hi = std::min(dims - 1, static_cast<int>(std::floor(b)));
  return true;
}

}  // namespace

Status AspectVoter::Init(const AspectTableView& table, const VoterConfig& config) {
  if (!table.valid()) {
    return Status::Error(StatusCode::kInvalidArgument, "aspect voter: no aspect table");
  }
  if (!(config.sigma_point_px > 0.05f && config.sigma_point_px < 100.0f) ||
      !(config.sigma_line_px > 0.05f && config.sigma_line_px < 100.0f) ||
      !(config.line_angle_window_deg > 0.0f && config.line_angle_window_deg <= 90.0f)) {
    return Status::Error(StatusCode::kInvalidArgument,
                         "aspect voter: sigmas %g / %g px or line angle window %g deg out of range",
                         config.sigma_point_px, config.sigma_line_px, config.line_angle_window_deg);
  }
  table_ = table;
  config_ = config;
  SH_RETURN_IF_ERROR(AllocateCounters());
  basis_keys_ = nullptr;
  inv_sigma2_point_ = 1.0f / (config.sigma_point_px * config.sigma_point_px);
  inv_sigma2_line_ = 1.0f / (config.sigma_line_px * config.sigma_line_px);
  stamp_ = 0;
  NextStamp();
  return Status::Ok();
}

size_t AspectVoter::BytesFor(uint32_t point_entries, uint32_t line_entries, uint32_t bases) {
  return 2 * InitBlock::PieceBytes<uint16_t>(point_entries) +
         2 * InitBlock::PieceBytes<uint16_t>(line_entries) +
         InitBlock::PieceBytes<uint16_t>(bases) + 3 * InitBlock::PieceBytes<uint32_t>(bases);
}

size_t AspectVoter::CounterBytes(const AspectTableView& table) {
  return BytesFor(table.point_entry_count(), table.line_entry_count(), table.basis_count());
}

bool AspectVoter::CarveCounters(uint8_t* data, size_t bytes) {
  const uint32_t points = table_.point_entry_count();
  const uint32_t lines = table_.line_entry_count();
  const uint32_t bases = table_.basis_count();
  size_t used = 0;
  point_stamp_ = InitBlock::CarvePiece<uint16_t>(data, bytes, &used, points);
  point_best_ = InitBlock::CarvePiece<uint16_t>(data, bytes, &used, points);
  line_stamp_ = InitBlock::CarvePiece<uint16_t>(data, bytes, &used, lines);
  line_best_ = InitBlock::CarvePiece<uint16_t>(data, bytes, &used, lines);
  basis_stamp_ = InitBlock::CarvePiece<uint16_t>(data, bytes, &used, bases);
  basis_point_sum_ = InitBlock::CarvePiece<uint32_t>(data, bytes, &used, bases);
  basis_line_sum_ = InitBlock::CarvePiece<uint32_t>(data, bytes, &used, bases);
  touched_ = InitBlock::CarvePiece<uint32_t>(data, bytes, &used, bases);
  if (touched_ == nullptr) {
    point_stamp_ = nullptr;  // not ready
    return false;
  }
  carved_points_ = points;
  carved_lines_ = lines;
  carved_bases_ = bases;
  return true;
}

Status AspectVoter::BorrowCounters(const AspectVoter& like, uint8_t* bytes, size_t size) {
  point_stamp_ = nullptr;
  borrowed_ = true;
  carved_points_ = carved_lines_ = carved_bases_ = 0;
  if (!like.ready()) {
    return Status::Error(StatusCode::kFailedPrecondition, "aspect voter: nothing to vote like");
  }
  const size_t need = CounterBytes(like.table_);
  if (bytes == nullptr || size < need) {
    return Status::Error(StatusCode::kResourceExhausted,
                         "aspect voter: %zu bytes lent for %zu bytes of counters", size, need);
  }
  table_ = like.table_;
  config_ = like.config_;
  basis_keys_ = like.basis_keys_;
  inv_sigma2_point_ = like.inv_sigma2_point_;
  inv_sigma2_line_ = like.inv_sigma2_line_;
  (void)CarveCounters(bytes, size);  // cannot fail: the block holds `need` bytes
  // The block's old contents mean nothing here: no stamp may match a later one.
  std::memset(point_stamp_, 0, size_t{carved_points_} * sizeof(uint16_t));
  std::memset(line_stamp_, 0, size_t{carved_lines_} * sizeof(uint16_t));
  std::memset(basis_stamp_, 0, size_t{carved_bases_} * sizeof(uint16_t));
  stamp_ = 0;
  NextStamp();
  return Status::Ok();
}

Status AspectVoter::AllocateCounters() {
  const uint32_t points = table_.point_entry_count();
  const uint32_t lines = table_.line_entry_count();
  const uint32_t bases = table_.basis_count();
  const size_t bytes = BytesFor(points, lines, bases);
  // The same block serves only the same layout: another table of the same total size would
  // overlap the arrays. A lent block is never kept.
  if (!borrowed_ && point_stamp_ != nullptr && points == carved_points_ && lines == carved_lines_ &&
      bases == carved_bases_) {
    std::memset(point_stamp_, 0, size_t{points} * sizeof(uint16_t));
    std::memset(line_stamp_, 0, size_t{lines} * sizeof(uint16_t));
    std::memset(basis_stamp_, 0, size_t{bases} * sizeof(uint16_t));
    return Status::Ok();
  }
  point_stamp_ = nullptr;
  borrowed_ = false;
  if (!block_.Allocate(bytes)) {
    return Status::Error(StatusCode::kResourceExhausted,
                         "aspect voter: cannot allocate %zu bytes of counters", bytes);
  }
  (void)CarveCounters(block_.data(), block_.bytes());  // cannot fail: sized by BytesFor
  return Status::Ok();
}

void AspectVoter::NextStamp() {
  n_touched_ = 0;
  if (++stamp_ != 0) return;
  // Wrapped: forget every old stamp so none can be mistaken for the new one.
  std::memset(point_stamp_, 0, size_t{table_.point_entry_count()} * sizeof(uint16_t));
  std::memset(line_stamp_, 0, size_t{table_.line_entry_count()} * sizeof(uint16_t));
  std::memset(basis_stamp_, 0, size_t{table_.basis_count()} * sizeof(uint16_t));
  stamp_ = 1;
}

void AspectVoter::AddPointVote(uint32_t entry, uint16_t vote) {
  const uint32_t b = table_.point_entries()[entry].basis;
  if (basis_stamp_[b] != stamp_) {
    basis_stamp_[b] = stamp_;
    basis_point_sum_[b] = 0;
    basis_line_sum_[b] = 0;
    touched_[n_touched_++] = b;
  }
  if (point_stamp_[entry] != stamp_) {
    point_stamp_[entry] = stamp_;
    point_best_[entry] = vote;
    basis_point_sum_[b] += vote;
  } else if (vote > point_best_[entry]) {
    basis_point_sum_[b] += vote - point_best_[entry];
    point_best_[entry] = vote;
  }
}

void AspectVoter::AddLineVote(uint32_t entry, uint16_t vote) {
  const uint32_t b = table_.line_entries()[entry].basis;
  if (basis_stamp_[b] != stamp_) {
    basis_stamp_[b] = stamp_;
    basis_point_sum_[b] = 0;
    basis_line_sum_[b] = 0;
    touched_[n_touched_++] = b;
  }
  if (line_stamp_[entry] != stamp_) {
    line_stamp_[entry] = stamp_;
    line_best_[entry] = vote;
    basis_line_sum_[b] += vote;
  } else if (vote > line_best_[entry]) {
    basis_line_sum_[b] += vote - line_best_[entry];
    line_best_[entry] = vote;
  }
}

float AspectVoter::LastVote(uint32_t basis) const {
  if (basis >= table_.basis_count() || basis_stamp_[basis] != stamp_) return 0.0f;
  const AspectBasis& rec = table_.basis(basis);
  float v = 0.0f;
  if (rec.n_point_entries > 0) {
    v += static_cast<float>(basis_point_sum_[basis]) * kVoteScale / rec.n_point_entries;
  }
  if (rec.n_line_entries > 0) {
    v += static_cast<float>(basis_line_sum_[basis]) * kVoteScale / rec.n_line_entries;
  }
  return v;
}

// Rows of bins crossed by the band {p : lo <= n . p <= hi, a0 <= u . p <= a1} (n, u unit and
// perpendicular), each with the range of columns that can hold such points; returns the count.
int AspectVoter::StripRows(const Grid2d& g, const Eigen::Vector2f& n, float lo, float hi,
                           const Eigen::Vector2f& u, float a0, float a1) {
  int n_rows = 0;
  // For a row [y0, y1], c . p in [l, h] allows x in an interval whose ends move linearly with
  // y; the union over the row is spanned by the ends at its two edges.
  auto x_range = [](const Eigen::Vector2f& c, float l, float h, float y0, float y1, float* x0,
                    float* x1) {
    if (std::fabs(c.x()) < 1e-6f) {
      const float v0 = c.y() * y0, v1 = c.y() * y1;
      if (std::max(v0, v1) < l || std::min(v0, v1) > h) return false;
      *x0 = -INFINITY;
      *x1 = INFINITY;
      return true;
    }
    const float e[4] = {(l - c.y() * y0) / c.x(), (h - c.y() * y0) / c.x(),
                        (l - c.y() * y1) / c.x(), (h - c.y() * y1) / c.x()};
    *x0 = std::min(std::min(e[0], e[1]), std::min(e[2], e[3]));
    *x1 = std::max(std::max(e[0], e[1]), std::max(e[2], e[3]));
    return true;
  };
  for (int y = 0; y < g.dims[1]; ++y) {
    const float y0 = g.min[1] + g.bin * static_cast<float>(y), y1 = y0 + g.bin;
    float xa0, xa1, xb0, xb1;
    if (!x_range(n, lo, hi, y0, y1, &xa0, &xa1) || !x_range(u, a0, a1, y0, y1, &xb0, &xb1)) {
      continue;
    }
    const float x_lo = std::max(std::max(xa0, xb0), g.min[0]);
    const float x_hi = std::min(std::min(xa1, xb1), g.min[0] + g.bin * g.dims[0]);
    if (!(x_hi >= x_lo)) continue;
    int x0, x1;
    if (!BinRange(0.5f * (x_lo + x_hi), 0.5f * (x_hi - x_lo), g.min[0], g.bin, g.dims[0], &x0,
                  &x1)) {
      continue;
    }
    row_y_[n_rows] = static_cast<uint16_t>(y);
    row_x0_[n_rows] = static_cast<uint16_t>(x0);
    row_x1_[n_rows] = static_cast<uint16_t>(x1);
    ++n_rows;
  }
  return n_rows;
}

// What one Vote() looks up with: the frame's inverse, the size slices the request's key range
// reaches, its squared reach (image units) and the basis keys that may receive votes.
struct AspectVoter::VoteSpan {
  const FrameInverse& fi;
  uint32_t size_lo, size_hi;
  float reach2;
  // Similarity frames scale hash space uniformly (G = |p1 - p0|^2 I): distances compare in
  // hash units directly.
  bool isotropic;
  // Bases outside the key range are skipped entry by entry (a compare instead of a vote).
  struct Keys {
    const float* keys;
    float lo, hi;
    bool Pass(uint32_t basis) const {
      return keys == nullptr || (keys[basis] >= lo && keys[basis] <= hi);
    }
  } keys;
};

int AspectVoter::Vote(const VoteScene& scene, const VoteRequest& request, AspectHypothesis* out,
                      int max_out, VoteCounts* counts) {
  NextStamp();
  const FrameInverse fi(request.frame);
  if (!(fi.min_scale > 1e-6f)) return 0;  // degenerate basis
  // Size slices the request's key range can reach (the keys are apparent sizes).
  const AspectHeader& header = table_.header();
  uint32_t size_lo = 0, size_hi = header.size_slices - 1u;
  if (std::isfinite(request.key_lo) && request.key_lo > 0.0f) {
    size_lo =
        SizeSlice(request.key_lo, header.log_size_min, header.log_size_max, header.size_slices);
  }
  if (std::isfinite(request.key_hi)) {
    size_hi =
        SizeSlice(request.key_hi, header.log_size_min, header.log_size_max, header.size_slices);
  }
  if (request.key_lo > request.key_hi || std::isnan(request.key_lo)) return 0;
  const VoteSpan span{fi,
                      size_lo,
                      size_hi,
                      request.reach * request.reach,
                      table_.basis_kind() == AspectBasisKind::kSimilarity,
                      {basis_keys_, request.key_lo, request.key_hi}};
  VoteCounts local;
  VotePoints(scene, request, span, &local);
  VoteLines(scene, request, span, &local);
  const int n_out = BestHypotheses(request.threshold, out, max_out);
  if (counts != nullptr) *counts = local;
  return n_out;
}

// The scene points' votes. The vote vanishes beyond 2 sigma (vote table cut-off), at most this
// far in hash units.
void AspectVoter::VotePoints(const VoteScene& scene, const VoteRequest& request,
                             const VoteSpan& span, VoteCounts* counts) {
  const FrameInverse& fi = span.fi;
  const ScenePoint2d* points = scene.points;
  const VoteSpan::Keys keys = span.keys;
  const uint32_t size_lo = span.size_lo, size_hi = span.size_hi;
  const float reach2 = span.reach2;
  const bool isotropic = span.isotropic;
  const Grid2d& pg = table_.point_grid();
  const uint32_t* point_bins = table_.point_bin_offsets();
  const AspectPointEntry* pe = table_.point_entries();
  const float point_reach = 2.0f * config_.sigma_point_px / fi.min_scale;
  const Eigen::Matrix2f& G = fi.metric;
  const float g00 = G(0, 0), g01x2 = 2.0f * G(0, 1), g11 = G(1, 1);
  VoteCounts local;
  for (int i = 0; i < scene.n_points; ++i) {
    if (scene.point_active != nullptr && scene.point_active[i] == 0) continue;
    bool skip = false;
    for (int k = 0; k < request.n_exclude; ++k) skip = skip || request.exclude[k] == i;
    if (skip) continue;
    if (!((points[i].xy - request.frame.origin).squaredNorm() <= reach2)) continue;
    const Eigen::Vector2f h = fi.ToHash(points[i].xy);
    int x0, x1, y0, y1;
    if (!BinRange(h.x(), point_reach, pg.min[0], pg.bin, pg.dims[0], &x0, &x1) ||
        !BinRange(h.y(), point_reach, pg.min[1], pg.bin, pg.dims[1], &y0, &y1)) {
      continue;
    }
    ++local.point_lookups;
    const float hx = h.x(), hy = h.y();
    // The point in raw Q4.12 units, and the squared raw distance within which an entry can
    // vote (for the isotropic metric of similarity frames: d^2 = G00 |dh|^2): one integer
    // test per entry, exact votes only for the few inside.
    const int32_t hx_raw = static_cast<int32_t>(std::lround(hx * (1.0f / kHashUnit)));
    const int32_t hy_raw = static_cast<int32_t>(std::lround(hy * (1.0f / kHashUnit)));
    const float reach_raw = (point_reach + 2.0f * kHashUnit) * (1.0f / kHashUnit);
    const int64_t reach2_raw = static_cast<int64_t>(reach_raw * reach_raw) + 1;
    for (uint32_t size = size_lo; size <= size_hi; ++size) {
      for (int y = y0; y <= y1; ++y) {
        const uint32_t row = size * pg.bin_count() + static_cast<uint32_t>(y) * pg.dims[0];
        const uint32_t begin = point_bins[row + x0], end = point_bins[row + x1 + 1];
        local.point_entries += end - begin;
        for (uint32_t e = begin; e < end; ++e) {
          const AspectPointEntry& entry = pe[e];
          if (isotropic) {
            const int32_t ix = hx_raw - entry.x, iy = hy_raw - entry.y;
            if (int64_t{ix} * ix + int64_t{iy} * iy > reach2_raw) continue;
          }
          // d^2 = dh^T G dh (eq. 2.10), written out.
          const float dx = hx - static_cast<float>(entry.x) * kHashUnit;
          const float dy = hy - static_cast<float>(entry.y) * kHashUnit;
          const float x = (g00 * dx * dx + g01x2 * dx * dy + g11 * dy * dy) * inv_sigma2_point_;
          if (!(x < static_cast<float>(kVoteCutoff))) continue;
          if (!keys.Pass(entry.basis)) continue;
          const uint16_t vote = lut_.VoteRaw(static_cast<uint32_t>(x * kVoteIndexScale));
          if (vote != 0) AddPointVote(e, vote);
        }
      }
    }
  }
  counts->point_lookups += local.point_lookups;
  counts->point_entries += local.point_entries;
}

// A scene line ready for the look-up in one frame: the hash line, its unit normal and offset
// along it (rho = normal . s), the rows of line-centre bins its strip crosses (row_y_, row_x0_,
// row_x1_) and the direction slices [first, last] (modulo the slice count) near its direction.
struct AspectVoter::LineScan {
  HashLine hl;
  Eigen::Vector2f normal{0, 1};
  float rho = 0;
  int n_rows = 0;
  int first = 0, last = -1;
};

// Prepares `line` for the look-up (LineScan); false when it is beyond the request's reach,
// degenerate in this frame, or its strip crosses no bin.
bool AspectVoter::ScanLine(const SceneLine2d& line, const VoteRequest& request,
                           const VoteSpan& span, LineScan* out) {
  const FrameInverse& fi = span.fi;
  {
    // Nearest point of the supported segment to the frame's origin.
    const Eigen::Vector2f w = request.frame.origin - line.point;
    const float t = std::max(line.t0, std::min(line.t1, w.dot(line.dir)));
    if (!((w - t * line.dir).squaredNorm() <= span.reach2)) return false;
  }
  const Eigen::Vector2f s = fi.ToHash(line.point);
  const Eigen::Vector2f v = fi.DirectionToHash(line.dir);
  const float vn = v.norm();
  if (!(vn > 1e-9f)) return false;
  const Eigen::Vector2f along = v / vn;
  const Eigen::Vector2f normal(-along.y(), along.x());
  // The centres near the line's supported extent, lengthened by a margin for segments the
  // image shows only in part: s + t v for t in [t0 - m, t1 + m] (image units), widened by
  // the strip in hash units.
  const float strip = 2.0f * config_.sigma_line_px / fi.min_scale;
  const float margin = std::max(config_.line_extent_margin_px, 0.5f * (line.t1 - line.t0));
  const float a0 = along.dot(s) + (line.t0 - margin) * vn - strip;
  const float a1 = along.dot(s) + (line.t1 + margin) * vn + strip;
  const float rho = normal.dot(s);
  const int n_rows = StripRows(table_.line_grid(), normal, rho - strip, rho + strip, along, a0, a1);
  if (n_rows == 0) return false;
  out->hl = MakeHashLine(fi.metric, s, v);
  out->normal = normal;
  out->rho = rho;
  out->n_rows = n_rows;
  // Slices overlapping [angle - window, angle + window], modulo 180 degrees.
  const uint32_t slices = table_.header().line_angle_slices;
  const bool keeps_angles = table_.basis_kind() == AspectBasisKind::kSimilarity;
  const float window = keeps_angles ? config_.line_angle_window_deg * (kPi / 180.0f) : kPi;
  const float slice_width = kPi / static_cast<float>(slices);
  float angle = std::atan2(v.y(), v.x());
  if (angle < 0) angle += kPi;
  out->first = static_cast<int>(std::floor((angle - window) / slice_width));
  out->last = std::min(out->first + static_cast<int>(slices) - 1,
                       static_cast<int>(std::floor((angle + window) / slice_width)));
  return true;
}

// The scene lines' votes. A model segment can vote only if its centre lies within 2 sigma of the
// scene line (the first term of eq. 6.1), so the look-up visits the strip of centre bins along
// the line, in the direction slices near the line's own direction.
void AspectVoter::VoteLines(const VoteScene& scene, const VoteRequest& request,
                            const VoteSpan& span, VoteCounts* counts) {
  const VoteSpan::Keys keys = span.keys;
  const uint32_t size_lo = span.size_lo, size_hi = span.size_hi;
  const bool isotropic = span.isotropic;
  const Eigen::Matrix2f& G = span.fi.metric;
  const float g00 = G(0, 0);
  const Grid2d& lg = table_.line_grid();
  const uint32_t slices = table_.header().line_angle_slices;
  const uint32_t slice_bins = lg.bin_count();
  const uint32_t* line_bins = table_.line_bin_offsets();
  const AspectLineEntry* le = table_.line_entries();
  // Isotropic quick tests, in hash units: the centre's distance to the line (the first term
  // of eq. 6.1 alone must stay within 2 sigma) and the tilt term (len^2 / 12) sin^2.
  const float across_max = 2.0f * config_.sigma_line_px / span.fi.min_scale;
  const float tilt_max = 4.0f * config_.sigma_line_px * config_.sigma_line_px / g00 * 12.0f;
  VoteCounts local;
  for (int i = 0; i < scene.n_lines; ++i) {
    if (scene.line_active != nullptr && scene.line_active[i] == 0) continue;
    LineScan scan;
    if (!ScanLine(scene.lines[i], request, span, &scan)) continue;
    ++local.line_lookups;
    const HashLine hl = scan.hl;
    const Eigen::Vector2f normal = scan.normal;
    const float rho = scan.rho;
    const int n_rows = scan.n_rows;
    for (int k = scan.first; k <= scan.last; ++k) {
      const int n_slices = static_cast<int>(slices);
      const uint32_t slice = static_cast<uint32_t>(((k % n_slices) + n_slices) % n_slices);
      for (uint32_t size = size_lo; size <= size_hi; ++size) {
        const uint32_t base = (size * slices + slice) * slice_bins;
        for (int r = 0; r < n_rows; ++r) {
          const uint32_t row = base + static_cast<uint32_t>(row_y_[r]) * lg.dims[0];
          const uint32_t begin = line_bins[row + row_x0_[r]], end = line_bins[row + row_x1_[r] + 1];
          local.line_entries += end - begin;
          for (uint32_t e = begin; e < end; ++e) {
            const AspectLineEntry& entry = le[e];
            const Eigen::Vector2f c(static_cast<float>(entry.cx) * kHashUnit,
                                    static_cast<float>(entry.cy) * kHashUnit);
            const Eigen::Vector2f u(static_cast<float>(entry.vx) * kUnitScale,
                                    static_cast<float>(entry.vy) * kUnitScale);
            const float len = static_cast<float>(entry.length) * kHashUnit;
            if (isotropic) {
              if (!(std::fabs(normal.dot(c) - rho) <= across_max)) continue;
              const float sin_angle = normal.dot(u);
              if (!(len * len * sin_angle * sin_angle <= tilt_max)) continue;
            }
            const float x = SegmentLineDistance2(G, hl, c, u, len) * inv_sigma2_line_;
            if (!(x < static_cast<float>(kVoteCutoff))) continue;
            if (!keys.Pass(entry.basis)) continue;
            const uint16_t vote = lut_.VoteRaw(static_cast<uint32_t>(x * kVoteIndexScale));
            if (vote != 0) AddLineVote(e, vote);
          }
        }
      }
    }
  }
  counts->line_lookups += local.line_lookups;
  counts->line_entries += local.line_entries;
}

// The bases of the last vote with at least `threshold`, best first, into out[0, max_out);
// returns their number.
int AspectVoter::BestHypotheses(float threshold, AspectHypothesis* out, int max_out) const {
  int n_out = 0;
  for (uint32_t k = 0; k < n_touched_; ++k) {
    const uint32_t b = touched_[k];
    const float v = LastVote(b);
    if (!(v >= threshold) || max_out <= 0) continue;
    if (n_out == max_out && !(v > out[n_out - 1].vote)) continue;
    int pos = n_out < max_out ? n_out++ : max_out - 1;
    while (pos > 0 && out[pos - 1].vote < v) {
      out[pos] = out[pos - 1];
      --pos;
    }
    out[pos] = {b, v};
  }
  return n_out;
}

}  // namespace sh
