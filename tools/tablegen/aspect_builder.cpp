#include "tools/tablegen/aspect_builder.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstring>
#include <memory>

#include "recog/base/crc32.hpp"
#include "recog/mono/aspect.hpp"
#include "recog/mono/frame2d.hpp"
#include "recog/mono/view_sphere.hpp"
#include "tables/aspect_view.hpp"
#include "tools/tablegen/blob_writer.hpp"
#include "tools/tablegen/model_symmetry.hpp"

namespace sh {
namespace {

// Views of the initial grid (15 degrees: 184; 5 degrees: 1652).
constexpr int kMaxGridViews = 4096;

struct BuiltPoint {
  Eigen::Vector2f h;
};
struct BuiltLine {
  Eigen::Vector2f centre, dir;
  float length;
};
struct BuiltBasis {
  AspectBasis record{};
  std::vector<BuiltPoint> points;
  std::vector<BuiltLine> lines;
};
struct BuiltAspect {
  AspectRecord record{};
  ViewDirection view;
  std::vector<BuiltBasis> bases;
};

// Hash coordinates beyond max_coordinate (basis lengths from the basis origin) are not stored:
// far features of short bases, whose bins would spread the grid thin.
bool InHashRange(const Eigen::Vector2f& h, float max_coordinate) {
  return std::fabs(h.x()) <= max_coordinate && std::fabs(h.y()) <= max_coordinate &&
         QHash::Representable(h.x()) && QHash::Representable(h.y());
}

// joined[i][j]: aspect corners i and j are the ends of one visible model edge, seen whole.
void JoinedCorners(const Model& m, const AspectView& a,
                   bool joined[kMaxModelCorners][kMaxModelCorners]) {
  for (int i = 0; i < a.n_corners; ++i) {
    for (int j = 0; j < a.n_corners; ++j) joined[i][j] = false;
  }
  for (int s = 0; s < a.n_segments; ++s) {
    const ModelEdge& e = m.edges[a.segments[s].edge];
    int i = -1, j = -1;
    for (int k = 0; k < a.n_corners; ++k) {
      if (a.corners[k].corner == e.a) i = k;
      if (a.corners[k].corner == e.b) j = k;
    }
    if (i < 0 || j < 0) continue;
    const float whole = (a.corners[j].xy - a.corners[i].xy).norm();
    if ((a.segments[s].b - a.segments[s].a).norm() >= 0.9f * whole)
      joined[i][j] = joined[j][i] = true;
  }
}

// Frames of every ordered corner pair (similarity) or triple (affine) with sides of at least
// min_side (normalised units; for triples: the triangle's smallest height). With edges_only,
// pairs must be joined by a visible edge, and triples made of two edges meeting at a corner
// (what an image shows as corners joined by lines, the scene bases recognition tries first).
void AddBases(const Model& m, const AspectView& a, AspectBasisKind kind, float min_side,
              bool edges_only, float max_coordinate, BuiltAspect* out) {
  const int n = a.n_corners;
  bool joined[kMaxModelCorners][kMaxModelCorners];
  JoinedCorners(m, a, joined);
  auto add = [&](int i, int j, int k) {
    const Frame2d f = kind == AspectBasisKind::kSimilarity
                          ? SimilarityFrame(a.corners[i].xy, a.corners[j].xy)
                          : AffineFrame(a.corners[i].xy, a.corners[j].xy, a.corners[k].xy);
    const FrameInverse fi(f);
    BuiltBasis b;
    b.record.model = out->record.model;
    b.record.corners[0] = a.corners[i].corner;
    b.record.corners[1] = a.corners[j].corner;
    b.record.corners[2] = k >= 0 ? a.corners[k].corner : 0xff;
    b.record.origin[0] = f.origin.x();
    b.record.origin[1] = f.origin.y();
    for (int c = 0; c < 4; ++c) b.record.axes[c] = f.axes.data()[c];  // column-major
    for (int p = 0; p < n; ++p) {
      if (p == i || p == j || p == k) continue;
      const Eigen::Vector2f h = fi.ToHash(a.corners[p].xy);
      if (InHashRange(h, max_coordinate)) b.points.push_back({h});
    }
    for (int s = 0; s < a.n_segments; ++s) {
      // The edges between basis corners lie on the basis frame's axes in every basis (one huge
      // bin at the origin, thesis 6.4.2) and say nothing: left out, like the basis line of the
      // 3-D line + point bases.
      const ModelEdge& e = m.edges[a.segments[s].edge];
      const bool on_basis =
          (e.a == b.record.corners[0] || e.a == b.record.corners[1] ||
           e.a == b.record.corners[2]) &&
          (e.b == b.record.corners[0] || e.b == b.record.corners[1] || e.b == b.record.corners[2]);
      if (on_basis) continue;
      const Eigen::Vector2f ha = fi.ToHash(a.segments[s].a), hb = fi.ToHash(a.segments[s].b);
      const Eigen::Vector2f centre = 0.5f * (ha + hb);
      const float length = (hb - ha).norm();
      if (!InHashRange(centre, max_coordinate) || !UQHashLength::Representable(length) ||
          !(length > 0.0f)) {
        continue;
      }
      b.lines.push_back({centre, (hb - ha) / length, length});
    }
    if (b.points.empty() && b.lines.empty()) return;
    b.record.n_point_entries = static_cast<uint16_t>(b.points.size());
    b.record.n_line_entries = static_cast<uint16_t>(b.lines.size());
    out->bases.push_back(std::move(b));
  };
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) {
      if (j == i) continue;
      const Eigen::Vector2f d01 = a.corners[j].xy - a.corners[i].xy;
      if (!(d01.norm() >= min_side)) continue;
      if (kind == AspectBasisKind::kSimilarity) {
        if (!edges_only || joined[i][j]) add(i, j, -1);
        continue;
      }
      for (int k = 0; k < n; ++k) {
        if (k == i || k == j) continue;
        // Two of the three sides edges (a path i-j-k in some order).
        const int edges = joined[i][j] + joined[j][k] + joined[i][k];
        if (edges_only && edges < 2) continue;
        const Eigen::Vector2f d02 = a.corners[k].xy - a.corners[i].xy;
        const Eigen::Vector2f d12 = a.corners[k].xy - a.corners[j].xy;
        const float area2 = std::fabs(d01.x() * d02.y() - d01.y() * d02.x());
        const float longest = std::max(d01.norm(), std::max(d02.norm(), d12.norm()));
        if (!(area2 / longest >= min_side)) continue;  // smallest height of the triangle
        add(i, j, k);
      }
    }
  }
}

Result<BuiltAspect> MakeAspect(const Model& m, uint16_t model_index, const ViewDirection& view,
                               const AspectBuildOptions& o) {
  AspectConfig config;
  config.distance_factor = o.distance_factor;
  config.min_corner_angle_deg = o.min_corner_angle_deg;
  config.min_segment_fraction = o.min_segment_fraction;
  auto aspect = std::make_unique<AspectView>();
  SH_RETURN_IF_ERROR(ComputeAspect(m, view.dir_model, config, aspect.get()));
  BuiltAspect out;
  out.view = view;
  AspectRecord& r = out.record;
  r.model = model_index;
  r.level = view.level;
  r.n_corners = static_cast<uint8_t>(aspect->n_corners);
  r.n_segments = static_cast<uint16_t>(aspect->n_segments);
  for (int k = 0; k < 3; ++k) r.dir_model[k] = aspect->dir_model[k];
  for (int row = 0; row < 3; ++row) {
    for (int col = 0; col < 3; ++col)
      r.cam_T_model[3 * row + col] = aspect->cam_T_model.R(row, col);
    r.cam_T_model[9 + row] = aspect->cam_T_model.t_mm[row];
  }
  r.distance_mm = aspect->distance_mm;
  r.radius = aspect->radius;
  // Too few corners for a basis plus one more feature: nothing to hash.
  if (aspect->n_corners > BasisCornerCount(o.kind)) {
    AddBases(m, *aspect, o.kind, o.min_basis_fraction * aspect->radius, o.edge_bases_only,
             o.max_hash_coordinate, &out);
  }
  return out;
}

Grid2d MakeGrid(const std::vector<Eigen::Vector2f>& pos, float bin) {
  Eigen::Vector2f lo(-1, -1), hi(1, 1);
  for (const auto& p : pos) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  Grid2d g{};
  g.bin = bin;
  for (int k = 0; k < 2; ++k) {
    g.min[k] = std::floor(lo[k] / bin) * bin;
    g.dims[k] = static_cast<uint16_t>(std::floor((hi[k] - g.min[k]) / bin) + 1);
  }
  return g;
}

uint32_t BinOf(const Grid2d& g, const Eigen::Vector2f& p) {
  int idx[2];
  for (int k = 0; k < 2; ++k) {
    idx[k] = std::clamp(static_cast<int>(std::floor((p[k] - g.min[k]) / g.bin)), 0, g.dims[k] - 1);
  }
  return static_cast<uint32_t>(idx[1]) * g.dims[0] + static_cast<uint32_t>(idx[0]);
}

AspectBuildParams ParamsOf(const AspectBuildOptions& o) {
  AspectBuildParams p{};
  p.initial_spacing_deg = o.initial_spacing_deg;
  p.distance_factor = o.distance_factor;
  p.min_corner_angle_deg = o.min_corner_angle_deg;
  p.min_segment_fraction = o.min_segment_fraction;
  p.min_basis_fraction = o.min_basis_fraction;
  p.test_sigma_point_px = o.test_sigma_point_px;
  p.test_sigma_line_px = o.test_sigma_line_px;
  p.test_scale_px = o.test_scale_px;
  p.test_vote_fraction = o.test_vote_fraction;
  p.test_pass_fraction = o.test_pass_fraction;
  p.max_levels = static_cast<uint8_t>(o.refine ? o.max_levels : 0);
  p.flags = o.edge_bases_only ? kAspectEdgeBasesOnly : 0;
  return p;
}

// Range of the bases' apparent sizes (natural log), for the size slices; a range of width 2
// when they are all alike.
void LogSizeRange(const std::vector<BuiltAspect>& aspects, float* lo, float* hi) {
  float log_size_min = INFINITY, log_size_max = -INFINITY;
  for (const BuiltAspect& a : aspects) {
    for (const BuiltBasis& b : a.bases) {
      const float size = std::log(AspectApparentSizeMm(a.record, b.record));
      log_size_min = std::min(log_size_min, size);
      log_size_max = std::max(log_size_max, size);
    }
  }
  if (!(log_size_max > log_size_min)) {
    log_size_min = std::isfinite(log_size_min) ? log_size_min - 1.0f : 0.0f;
    log_size_max = log_size_min + 2.0f;
  }
  *lo = log_size_min;
  *hi = log_size_max;
}

// The records and entries of a table in build order, with what each entry is binned by: its
// stored (quantised) position or centre, and its size slice (lines: size and angle slice).
struct FlatTable {
  float log_size_min = 0, log_size_max = 0;
  std::vector<AspectRecord> aspect_records;
  std::vector<AspectBasis> basis_records;
  std::vector<AspectPointEntry> points;
  std::vector<AspectLineEntry> lines;
  std::vector<Eigen::Vector2f> point_pos, line_centre;
  std::vector<uint32_t> point_size_slice, line_slice;
};

// Appends the point and line entries of basis `basis_index` (in size slice `size_slice`).
void AddEntries(const BuiltBasis& b, uint32_t basis_index, uint32_t size_slice,
                uint32_t angle_slices, FlatTable* t) {
  for (const BuiltPoint& p : b.points) {
    // hash units -> Q4.12: round(h * 4096), within range (checked when the basis was made).
    AspectPointEntry e{QHash::FromDouble(p.h.x()).raw(), QHash::FromDouble(p.h.y()).raw(),
                       basis_index};
    // Binned by the stored (quantised) coordinates, which are what look-ups compare with.
    t->point_pos.emplace_back(QHash::FromRaw(e.x).ToFloat(), QHash::FromRaw(e.y).ToFloat());
    t->point_size_slice.push_back(size_slice);
    t->points.push_back(e);
  }
  for (const BuiltLine& l : b.lines) {
    AspectLineEntry e{};
    e.cx = QHash::FromDouble(l.centre.x()).raw();  // hash units -> Q4.12
    e.cy = QHash::FromDouble(l.centre.y()).raw();
    e.vx = QUnit::FromDouble(l.dir.x()).raw();  // unit components -> Q2.14
    e.vy = QUnit::FromDouble(l.dir.y()).raw();
    e.length = UQHashLength::FromDouble(l.length).raw();  // hash units -> UQ4.12
    e.basis = basis_index;
    // Binned by the stored (quantised) centre and direction.
    t->line_centre.emplace_back(QHash::FromRaw(e.cx).ToFloat(), QHash::FromRaw(e.cy).ToFloat());
    t->line_slice.push_back(size_slice * angle_slices +
                            LineAngleSlice(QUnit::FromRaw(e.vx).ToFloat(),
                                           QUnit::FromRaw(e.vy).ToFloat(), angle_slices));
    t->lines.push_back(e);
  }
}

// The aspects (their bases in order) as records and entries.
FlatTable FlattenAspects(const std::vector<BuiltAspect>& aspects, uint32_t size_slices,
                         uint32_t angle_slices) {
  FlatTable t;
  LogSizeRange(aspects, &t.log_size_min, &t.log_size_max);
  for (const BuiltAspect& a : aspects) {
    AspectRecord r = a.record;
    r.first_basis = static_cast<uint32_t>(t.basis_records.size());
    r.n_bases = static_cast<uint32_t>(a.bases.size());
    const uint32_t aspect_index = static_cast<uint32_t>(t.aspect_records.size());
    t.aspect_records.push_back(r);
    for (const BuiltBasis& b : a.bases) {
      const uint32_t basis_index = static_cast<uint32_t>(t.basis_records.size());
      AspectBasis br = b.record;
      br.aspect = aspect_index;
      t.basis_records.push_back(br);
      const uint32_t size_slice =
          SizeSlice(AspectApparentSizeMm(r, br), t.log_size_min, t.log_size_max, size_slices);
      AddEntries(b, basis_index, size_slice, angle_slices, &t);
    }
  }
  return t;
}

// The entries sorted by bin, with the bins' offsets and the grids.
struct BinnedEntries {
  Grid2d point_grid{}, line_grid{};
  std::vector<uint32_t> point_offsets, line_offsets;
  std::vector<AspectPointEntry> points_sorted;
  std::vector<AspectLineEntry> lines_sorted;
  uint32_t max_point_bin = 0, max_line_bin = 0;
};

Status BinEntries(const FlatTable& t, const AspectBuildOptions& o, uint32_t size_slices,
                  uint32_t angle_slices, BinnedEntries* out) {
  const std::vector<Eigen::Vector2f>& point_pos = t.point_pos;
  const std::vector<Eigen::Vector2f>& line_centre = t.line_centre;
  const Grid2d point_grid = MakeGrid(point_pos, o.point_bin);
  const Grid2d line_grid = MakeGrid(line_centre, o.line_bin);
  const uint32_t point_bins = point_grid.bin_count() * size_slices;
  const uint32_t line_bins = line_grid.bin_count() * size_slices * angle_slices;
  if (point_bins > kMaxAspectBins || line_bins > kMaxAspectBins) {
    return Status::Error(StatusCode::kResourceExhausted, "aspect hash grid has too many bins");
  }
  std::vector<uint32_t> point_bin_of, line_bin_of, point_order, line_order;
  for (size_t i = 0; i < point_pos.size(); ++i) {
    point_bin_of.push_back(t.point_size_slice[i] * point_grid.bin_count() +
                           BinOf(point_grid, point_pos[i]));
  }
  for (size_t i = 0; i < line_centre.size(); ++i) {
    line_bin_of.push_back(t.line_slice[i] * line_grid.bin_count() +
                          BinOf(line_grid, line_centre[i]));
  }
  out->point_grid = point_grid;
  out->line_grid = line_grid;
  out->point_offsets = SortByBin(point_bin_of, point_bins, &point_order, &out->max_point_bin);
  out->line_offsets = SortByBin(line_bin_of, line_bins, &line_order, &out->max_line_bin);
  out->points_sorted.resize(t.points.size());
  out->lines_sorted.resize(t.lines.size());
  for (size_t i = 0; i < t.points.size(); ++i) out->points_sorted[i] = t.points[point_order[i]];
  for (size_t i = 0; i < t.lines.size(); ++i) out->lines_sorted[i] = t.lines[line_order[i]];
  return Status::Ok();
}

// The blob (aspect_format.hpp) of `models`' table: header, sections, CRC.
std::vector<uint8_t> WriteAspectBlob(const std::vector<Model>& models, const FlatTable& t,
                                     const BinnedEntries& binned, const AspectBuildOptions& o,
                                     uint32_t size_slices, uint32_t angle_slices) {
  const std::vector<AspectRecord>& aspect_records = t.aspect_records;
  const std::vector<AspectBasis>& basis_records = t.basis_records;
  const std::vector<uint32_t>& point_offsets = binned.point_offsets;
  const std::vector<uint32_t>& line_offsets = binned.line_offsets;
  const std::vector<AspectPointEntry>& points_sorted = binned.points_sorted;
  const std::vector<AspectLineEntry>& lines_sorted = binned.lines_sorted;
  AspectHeader h{};
  std::memcpy(h.magic, kAspectMagic, sizeof(kAspectMagic));
  h.format_version = kAspectFormatVersion;
  h.basis_kind = static_cast<uint8_t>(o.kind);
  h.header_size = sizeof(AspectHeader);
  h.n_models = static_cast<uint32_t>(models.size());
  h.n_aspects = static_cast<uint32_t>(aspect_records.size());
  h.n_bases = static_cast<uint32_t>(basis_records.size());
  h.n_point_entries = static_cast<uint32_t>(t.points.size());
  h.n_line_entries = static_cast<uint32_t>(t.lines.size());
  h.max_point_bin_entries = binned.max_point_bin;
  h.max_line_bin_entries = binned.max_line_bin;
  h.point_grid = binned.point_grid;
  h.line_grid = binned.line_grid;
  h.line_angle_slices = static_cast<uint16_t>(angle_slices);
  h.size_slices = static_cast<uint16_t>(size_slices);
  h.log_size_min = t.log_size_min;
  h.log_size_max = t.log_size_max;
  h.build = ParamsOf(o);
  SectionLayout layout(sizeof(AspectHeader));
  layout.Place(&h.models, models.size() * sizeof(Model));
  layout.Place(&h.aspects, aspect_records.size() * sizeof(AspectRecord));
  layout.Place(&h.bases, basis_records.size() * sizeof(AspectBasis));
  layout.Place(&h.point_bins, point_offsets.size() * sizeof(uint32_t));
  layout.Place(&h.point_entries, points_sorted.size() * sizeof(AspectPointEntry));
  layout.Place(&h.line_bins, line_offsets.size() * sizeof(uint32_t));
  layout.Place(&h.line_entries, lines_sorted.size() * sizeof(AspectLineEntry));
  h.total_size = layout.total_size();

  std::vector<uint8_t> blob(layout.total_size(), 0);
  PutSection(blob, h.models, models.data(), models.size());
  PutSection(blob, h.aspects, aspect_records.data(), aspect_records.size());
  PutSection(blob, h.bases, basis_records.data(), basis_records.size());
  PutSection(blob, h.point_bins, point_offsets.data(), point_offsets.size());
  PutSection(blob, h.point_entries, points_sorted.data(), points_sorted.size());
  PutSection(blob, h.line_bins, line_offsets.data(), line_offsets.size());
  PutSection(blob, h.line_entries, lines_sorted.data(), lines_sorted.size());
  SealBlob(blob, h);
  return blob;
}

// Serialises aspects (their bases in order) of `models` into a blob.
Result<std::vector<uint8_t>> Serialise(const std::vector<Model>& models,
                                       const std::vector<BuiltAspect>& aspects,
                                       const AspectBuildOptions& o, AspectBuildReport* rep) {
  const uint32_t size_slices = static_cast<uint32_t>(o.size_slices);
  const uint32_t angle_slices = static_cast<uint32_t>(o.line_angle_slices);
  const FlatTable t = FlattenAspects(aspects, size_slices, angle_slices);
  if (models.size() > kMaxAspectModels || t.aspect_records.size() > kMaxAspects ||
      t.basis_records.size() > kMaxAspectBases || t.points.size() > kMaxAspectPointEntries ||
      t.lines.size() > kMaxAspectLineEntries) {
    return Status::Error(StatusCode::kResourceExhausted,
                         "aspect table too large for this build: %zu models, %zu aspects, %zu "
                         "bases, %zu point and %zu line entries (limits %u, %u, %u, %u, %u)",
                         models.size(), t.aspect_records.size(), t.basis_records.size(),
                         t.points.size(), t.lines.size(), kMaxAspectModels, kMaxAspects,
                         kMaxAspectBases, kMaxAspectPointEntries, kMaxAspectLineEntries);
  }
  BinnedEntries binned;
  SH_RETURN_IF_ERROR(BinEntries(t, o, size_slices, angle_slices, &binned));
  if (rep != nullptr) {
    rep->max_point_bin_entries = binned.max_point_bin;
    rep->max_line_bin_entries = binned.max_line_bin;
  }
  return WriteAspectBlob(models, t, binned, o, size_slices, angle_slices);
}

// Thesis 6.4.1: a test view passes when at least test_pass_fraction of its scene bases give
// some aspect of the same model a normalised vote of at least test_vote_fraction of the
// maximum (2). The test view is scaled so that its radius is test_scale_px pixels.
bool TestViewPasses(const Model& m, const AspectView& view, AspectVoter& voter,
                    const AspectBuildOptions& o) {
  bool joined[kMaxModelCorners][kMaxModelCorners];
  JoinedCorners(m, view, joined);
  const float scale = o.test_scale_px / std::max(1e-6f, view.radius);
  std::vector<ScenePoint2d> points(view.n_corners);
  std::vector<SceneLine2d> lines(view.n_segments);
  for (int i = 0; i < view.n_corners; ++i) points[i].xy = scale * view.corners[i].xy;
  for (int s = 0; s < view.n_segments; ++s) {
    const Eigen::Vector2f a = scale * view.segments[s].a, b = scale * view.segments[s].b;
    lines[s].point = a;
    lines[s].dir = (b - a).normalized();
    lines[s].t0 = 0;
    lines[s].t1 = (b - a).norm();
  }
  const float min_side = o.min_basis_fraction * o.test_scale_px;
  const float needed = o.test_vote_fraction * 2.0f;
  int bases = 0, passed = 0;
  const int nc = BasisCornerCount(o.kind);
  // Scene bases: unordered pairs or triples (the table holds every ordering); k = -1 for pairs.
  for (int i = 0; i < view.n_corners; ++i) {
    for (int j = i + 1; j < view.n_corners; ++j) {
      const int k_begin = nc == 3 ? j + 1 : -1, k_end = nc == 3 ? view.n_corners : 0;
      for (int k = k_begin; k < k_end; ++k) {
        const Eigen::Vector2f p0 = points[i].xy, p1 = points[j].xy;
        if (!((p1 - p0).norm() >= min_side)) continue;
        if (o.edge_bases_only) {
          // Pairs: joined; triples: two of the sides joined.
          const int edges = joined[i][j] + (nc == 3 ? joined[j][k] + joined[i][k] : 0);
          if (edges < nc - 1) continue;
        }
        Frame2d f;
        int exclude[3] = {i, j, k};
        if (nc == 2) {
          f = SimilarityFrame(p0, p1);
        } else {
          const Eigen::Vector2f p2 = points[k].xy;
          const Eigen::Vector2f d01 = p1 - p0, d02 = p2 - p0, d12 = p2 - p1;
          const float area2 = std::fabs(d01.x() * d02.y() - d01.y() * d02.x());
          const float longest = std::max(d01.norm(), std::max(d02.norm(), d12.norm()));
          if (!(area2 / longest >= min_side)) continue;
          f = AffineFrame(p0, p1, p2);
        }
        ++bases;
        AspectHypothesis best;
        VoteScene scene;
        scene.points = points.data();
        scene.n_points = view.n_corners;
        scene.lines = lines.data();
        scene.n_lines = view.n_segments;
        VoteRequest request;
        request.frame = f;
        for (int q = 0; q < nc; ++q) request.exclude[q] = exclude[q];
        request.n_exclude = nc;
        request.threshold = needed;
        if (voter.Vote(scene, request, &best, 1) > 0) ++passed;
      }
    }
  }
  return bases == 0 || static_cast<float>(passed) >= o.test_pass_fraction * bases;
}

// The first option outside its range, named with its range, so that the user knows which to fix.
Status CheckBuildOptions(const AspectBuildOptions& o) {
  struct Range {
    const char* name;
    double value, min, max;
  };
  const double slices = kMaxAspectAngleSlices;
  const Range ranges[] = {
      {"initial spacing (--spacing, degrees)", o.initial_spacing_deg, 2, 90},
      {"refinement levels (--levels)", double(o.max_levels), 0, 6},
      {"direction slices (--slices D,S: D)", double(o.line_angle_slices), 1, slices},
      {"size slices (--slices D,S: S)", double(o.size_slices), 1, slices},
      {"basis fraction", o.min_basis_fraction, 1e-9, 1e9},
      {"test scale (px)", o.test_scale_px, 1.000001, 1e9},
      {"point bin", o.point_bin, 1e-9, 1e9},
      {"line bin", o.line_bin, 1e-9, 1e9},
  };
  for (const Range& r : ranges) {
    if (!(r.value >= r.min && r.value <= r.max)) {
      return Status::Error(StatusCode::kInvalidArgument, "aspect table: %s is %g, outside %g..%g",
                           r.name, r.value, r.min, r.max);
    }
  }
  return Status::Ok();
}

}  // namespace

Result<std::vector<uint8_t>> BuildAspectBlob(std::vector<Model> models, const AspectBuildOptions& o,
                                             AspectBuildReport* report) {
  if (models.empty() || models.size() > kMaxAspectModels) {
    return Status::Error(StatusCode::kInvalidArgument, "aspect table: need 1..%u models, got %zu",
                         kMaxAspectModels, models.size());
  }
  SH_RETURN_IF_ERROR(CheckBuildOptions(o));
  AspectBuildReport local;
  AspectBuildReport& rep = report ? *report : local;
  rep = {};
  std::unique_ptr<ViewDirection[]> grid(new ViewDirection[kMaxGridViews]);
  const int n_grid = InitialViewGrid(o.initial_spacing_deg, grid.get(), kMaxGridViews);
  if (n_grid > kMaxGridViews) {
    return Status::Error(StatusCode::kInvalidArgument, "aspect table: initial grid too fine");
  }
  auto voter = std::make_unique<AspectVoter>();
  auto test_view = std::make_unique<AspectView>();
  AspectConfig aspect_config;
  aspect_config.distance_factor = o.distance_factor;
  aspect_config.min_corner_angle_deg = o.min_corner_angle_deg;
  aspect_config.min_segment_fraction = o.min_segment_fraction;
  VoterConfig voter_config;
  voter_config.sigma_point_px = o.test_sigma_point_px;
  voter_config.sigma_line_px = o.test_sigma_line_px;

  std::vector<BuiltAspect> all;
  for (size_t mi = 0; mi < models.size(); ++mi) {
    Model& m = models[mi];
    const std::vector<SymmetryAction> group = FindSymmetries(m);
    if (group.empty()) {
      return Status::Error(StatusCode::kInvalidArgument,
                           "model '%s': cannot determine its symmetry group", m.name);
    }
    StoreSymmetries(m, group);
    AspectModelReport mr;
    mr.model = m.name;
    const uint16_t index = static_cast<uint16_t>(mi);
    // The grid's covering radius is about 0.7 spacings: one spacing keeps every view covered.
    const float margin = o.initial_spacing_deg;
    std::vector<BuiltAspect> aspects;
    for (int v = 0; v < n_grid; ++v) {
      if (!InSymmetryDomain(m, grid[v].dir_model, margin)) continue;
      Result<BuiltAspect> a = MakeAspect(m, 0, grid[v], o);
      if (!a.ok()) return a.status();
      aspects.push_back(std::move(*a));
    }
    // Refinement (thesis 6.3): test views half way around each view of the newest level; when
    // one fails, the four become aspects of the next level, and are tested in turn.
    size_t level_begin = 0;
    for (int level = 0; o.refine && level < o.max_levels; ++level) {
      Result<std::vector<uint8_t>> blob = Serialise({m}, aspects, o, nullptr);
      if (!blob.ok()) return blob.status();
      std::vector<uint64_t> aligned((blob->size() + 7) / 8);
      std::memcpy(aligned.data(), blob->data(), blob->size());
      Result<AspectTableView> view = AspectTableView::Open(aligned.data(), blob->size());
      if (!view.ok()) return view.status();
      SH_RETURN_IF_ERROR(voter->Init(*view, voter_config));
      const size_t level_end = aspects.size();
      std::vector<BuiltAspect> added;
      for (size_t a = level_begin; a < level_end; ++a) {
        ViewDirection tests[4];
        RefinementViews(aspects[a].view, tests);
        bool failed = false;
        for (const ViewDirection& t : tests) {
          if (!InSymmetryDomain(m, t.dir_model, margin)) continue;
          SH_RETURN_IF_ERROR(ComputeAspect(m, t.dir_model, aspect_config, test_view.get()));
          ++mr.test_views;
          if (!TestViewPasses(m, *test_view, *voter, o)) failed = true;
        }
        if (!failed) continue;
        ++mr.failed_test_views;
        for (const ViewDirection& t : tests) {
          if (!InSymmetryDomain(m, t.dir_model, margin)) continue;
          Result<BuiltAspect> na = MakeAspect(m, 0, t, o);
          if (!na.ok()) return na.status();
          added.push_back(std::move(*na));
        }
      }
      if (added.empty()) break;
      level_begin = aspects.size();
      for (auto& a : added) aspects.push_back(std::move(a));
    }
    for (const BuiltAspect& a : aspects) {
      ++mr.aspects;
      ++mr.aspects_per_level[std::min<int>(7, a.view.level)];
      mr.bases += static_cast<uint32_t>(a.bases.size());
      for (const BuiltBasis& b : a.bases) {
        mr.point_entries += static_cast<uint32_t>(b.points.size());
        mr.line_entries += static_cast<uint32_t>(b.lines.size());
      }
    }
    rep.aspects += mr.aspects;
    rep.bases += mr.bases;
    rep.point_entries += mr.point_entries;
    rep.line_entries += mr.line_entries;
    rep.per_model.push_back(mr);
    for (auto& a : aspects) {
      // Built as model 0 of a one-model table for the refinement tests.
      a.record.model = index;
      for (BuiltBasis& b : a.bases) b.record.model = index;
      all.push_back(std::move(a));
    }
  }
  return Serialise(models, all, o, &rep);
}

}  // namespace sh
