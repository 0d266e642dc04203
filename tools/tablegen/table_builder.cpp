#include "tools/tablegen/table_builder.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>

#include "recog/base/printable.hpp"
#include "recog/model/model_features.hpp"
#include "tables/table_format.hpp"
#include "tools/tablegen/blob_writer.hpp"
#include "tools/tablegen/model_symmetry.hpp"

namespace sh {
namespace {

// A model basis by the features that define it: corners (i, j, k) for three-point bases,
// (edge, edge) for two lines, (edge, corner) for line+point; `signs` picks the line directions.
struct BasisKey {
  std::array<int, 3> f{};
  int signs = 0;
  bool operator<(const BasisKey& o) const { return std::tie(f, signs) < std::tie(o.f, o.signs); }
};

struct StoredPoint {
  Eigen::Vector3f p;
};
struct StoredLine {
  Eigen::Vector3f centre, direction, support;
  float length = 0.0f;
};

struct BuiltBasis {
  BasisRecord record{};
  std::vector<StoredPoint> points;
  std::vector<StoredLine> lines;
};

Eigen::Vector3f QuantisedMm(const Eigen::Vector3f& p) {
  return {QCoordMm::FromDouble(p.x()).ToFloat(), QCoordMm::FromDouble(p.y()).ToFloat(),
          QCoordMm::FromDouble(p.z()).ToFloat()};
}

BasisLine3 EdgeLine(const Model& m, int e, bool reversed) {
  const Eigen::Vector3f a = m.corner(m.edges[e].a), b = m.corner(m.edges[e].b);
  Eigen::Vector3f d = (b - a).normalized();
  if (reversed) d = -d;
  return {a, d};
}

// Image of a basis under a symmetry.
BasisKey Apply(HashFunction hf, const SymmetryAction& g, const BasisKey& k) {
  BasisKey r = k;
  if (UsesThreePoints(hf)) {
    for (int i = 0; i < 3; ++i) r.f[i] = g.corner_map[k.f[i]];
  } else if (hf == HashFunction::kTwoLines) {
    r.f[0] = g.edge_map[k.f[0]];
    r.f[1] = g.edge_map[k.f[1]];
    r.signs = (k.signs & 1) ^ int(g.edge_flipped[k.f[0]]);
    r.signs |= ((k.signs >> 1) & 1) ^ int(g.edge_flipped[k.f[1]]) ? 2 : 0;
  } else {
    r.f[0] = g.edge_map[k.f[0]];
    r.f[1] = g.corner_map[k.f[1]];
    r.signs = k.signs ^ int(g.edge_flipped[k.f[0]]);
  }
  return r;
}

bool IsCanonical(HashFunction hf, const std::vector<SymmetryAction>& group, const BasisKey& k) {
  for (const auto& g : group) {
    if (Apply(hf, g, k) < k) return false;
  }
  return true;
}

void AddLine(const Model& m, int e, const RigidTransform& basis_T_model, BuiltBasis& out) {
  const Eigen::Vector3f a = basis_T_model * m.corner(m.edges[e].a);
  const Eigen::Vector3f b = basis_T_model * m.corner(m.edges[e].b);
  StoredLine l;
  l.length = (b - a).norm();
  l.direction = (b - a) / l.length;
  l.centre = 0.5f * (a + b);
  l.support = SupportVector(a, l.direction);
  out.lines.push_back(l);
}

// Builds one basis' entries, or returns false if the basis is geometrically invalid.
bool BuildBasis(const Model& m, const ModelFeatures& features, uint16_t model_index,
                HashFunction hf, const BasisLimits& limits, const BasisKey& k, BuiltBasis& out) {
  RigidTransform basis_T_model;
  out = {};
  if (UsesThreePoints(hf)) {
    const Eigen::Vector3f p0 = m.corner(k.f[0]), p1 = m.corner(k.f[1]), p2 = m.corner(k.f[2]);
    if (!ThreePointFrame(hf, p0, p1, p2, limits, &basis_T_model)) return false;
    for (int i = 0; i < m.n_corners; ++i) {
      if (features.corner(i) && i != k.f[0] && i != k.f[1] && i != k.f[2])
        out.points.push_back({basis_T_model * m.corner(i)});
    }
    out.points.push_back({TriangleShapePoint(p0, p1, p2)});
    for (int e = 0; e < m.n_edges; ++e) {
      if (features.line(e)) AddLine(m, e, basis_T_model, out);
    }
  } else if (hf == HashFunction::kTwoLines) {
    if (k.f[0] == k.f[1]) return false;
    if (!TwoLineFrame(EdgeLine(m, k.f[0], k.signs & 1), EdgeLine(m, k.f[1], k.signs & 2), limits,
                      &basis_T_model))
      return false;
    for (int i = 0; i < m.n_corners; ++i) {
      if (features.corner(i)) out.points.push_back({basis_T_model * m.corner(i)});
    }
    for (int e = 0; e < m.n_edges; ++e) {
      if (features.line(e)) AddLine(m, e, basis_T_model, out);
    }
  } else {
    const ModelEdge& edge = m.edges[k.f[0]];
    if (k.f[1] == edge.a || k.f[1] == edge.b) return false;
    if (!LinePointFrame(hf, EdgeLine(m, k.f[0], k.signs & 1), m.corner(k.f[1]), limits,
                        &basis_T_model))
      return false;
    for (int i = 0; i < m.n_corners; ++i) {
      if (features.corner(i) && i != k.f[1]) out.points.push_back({basis_T_model * m.corner(i)});
    }
    for (int e = 0; e < m.n_edges; ++e) {
      if (features.line(e) && e != k.f[0]) AddLine(m, e, basis_T_model, out);
    }
  }
  BasisRecord& r = out.record;
  r.model = model_index;
  for (int i = 0; i < 3; ++i) r.features[i] = static_cast<uint8_t>(std::max(0, k.f[i]));
  r.signs = static_cast<uint8_t>(k.signs);
  r.n_point_entries = static_cast<uint16_t>(out.points.size());
  r.n_line_entries = static_cast<uint16_t>(out.lines.size());
  Eigen::Map<Eigen::Matrix<float, 3, 3, Eigen::RowMajor>>(r.basis_T_model) = basis_T_model.R;
  for (int i = 0; i < 3; ++i) r.basis_T_model[9 + i] = basis_T_model.t_mm[i];
  return true;
}

// Bases of hashed features only (model_features.hpp).
std::vector<BasisKey> EnumerateKeys(const Model& m, const ModelFeatures& f, HashFunction hf) {
  std::vector<BasisKey> keys;
  if (UsesThreePoints(hf)) {
    for (int i = 0; i < m.n_corners; ++i) {
      for (int j = 0; j < m.n_corners; ++j) {
        for (int k = 0; k < m.n_corners; ++k) {
          const bool hashed = f.corner(i) && f.corner(j) && f.corner(k);
          if (hashed && i != j && j != k && i != k) keys.push_back({{i, j, k}, 0});
        }
      }
    }
  } else if (hf == HashFunction::kTwoLines) {
    for (int i = 0; i < m.n_edges; ++i) {
      for (int j = 0; j < m.n_edges; ++j) {
        for (int s = 0; s < 4; ++s) {
          if (f.line(i) && f.line(j) && i != j) keys.push_back({{i, j, 0}, s});
        }
      }
    }
  } else {
    for (int e = 0; e < m.n_edges; ++e) {
      for (int c = 0; c < m.n_corners; ++c) {
        for (int s = 0; s < 2; ++s) {
          if (f.line(e) && f.corner(c)) keys.push_back({{e, c, 0}, s});
        }
      }
    }
  }
  return keys;
}

GridGeometry MakeGrid(const std::vector<Eigen::Vector3f>& values, float bin_mm) {
  Eigen::Vector3f lo = Eigen::Vector3f::Constant(-bin_mm), hi = Eigen::Vector3f::Constant(bin_mm);
  for (const auto& v : values) {
    lo = lo.cwiseMin(v);
    hi = hi.cwiseMax(v);
  }
  GridGeometry g{};
  g.bin_mm = bin_mm;
  for (int i = 0; i < 3; ++i) {
    const float start = std::floor(lo[i] / bin_mm) * bin_mm;
    const int bins = std::max(1, int(std::floor(hi[i] / bin_mm)) + 1 - int(start / bin_mm));
    g.min_mm[i] = start;
    g.dims[i] = static_cast<uint16_t>(bins);
  }
  return g;
}

uint32_t BinOf(const GridGeometry& g, const Eigen::Vector3f& p) {
  uint32_t idx[3];
  for (int i = 0; i < 3; ++i) {
    const int b = int(std::floor((p[i] - g.min_mm[i]) / g.bin_mm));
    idx[i] = uint32_t(std::clamp(b, 0, int(g.dims[i]) - 1));
  }
  return (idx[2] * g.dims[1] + idx[1]) * g.dims[0] + idx[0];
}

}  // namespace

Result<std::vector<uint8_t>> BuildTableBlob(std::vector<Model> models,
                                            const TableBuildOptions& options,
                                            TableBuildReport* report) {
  const HashFunction hf = options.hash_function;
  if (models.empty() || models.size() > kMaxTableModels) {
    return Status::Error(StatusCode::kInvalidArgument, "need 1..%u models, got %zu",
                         kMaxTableModels, models.size());
  }
  TableBuildReport local;
  TableBuildReport& rep = report ? *report : local;
  rep = {};

  std::vector<BuiltBasis> bases;
  for (size_t mi = 0; mi < models.size(); ++mi) {
    Model& m = models[mi];
    const std::vector<SymmetryAction> group = FindSymmetries(m);
    if (group.empty()) {
      char name[kPrintableNameBytes];
      return Status::Error(StatusCode::kInvalidArgument,
                           "model '%s': cannot determine its symmetry group",
                           Printable(m.name, sizeof(m.name), name, sizeof(name)));
    }
    StoreSymmetries(m, group);
    ModelBasisCount count;
    count.model = m.name;
    const ModelFeatures features = FeaturesOf(m);
    for (const BasisKey& key : EnumerateKeys(m, features, hf)) {
      if (!IsCanonical(hf, group, key)) continue;
      BuiltBasis b;
      if (!BuildBasis(m, features, uint16_t(mi), hf, options.limits, key, b)) continue;
      ++count.bases;
      count.point_entries += b.record.n_point_entries;
      count.line_entries += b.record.n_line_entries;
      bases.push_back(std::move(b));
    }
    rep.per_model.push_back(count);
    rep.bases += count.bases;
    rep.point_entries += count.point_entries;
    rep.line_entries += count.line_entries;
  }
  if (bases.size() > kMaxTableBases || rep.point_entries > kMaxTablePointEntries ||
      rep.line_entries > kMaxTableLineEntries) {
    return Status::Error(StatusCode::kResourceExhausted,
                         "tables too large for this build: %u bases, %u point and %u line entries",
                         rep.bases, rep.point_entries, rep.line_entries);
  }

  // Flatten and bin.
  std::vector<Eigen::Vector3f> point_pos, line_support;
  std::vector<PointEntry> points;
  std::vector<LineEntry> lines;
  for (uint32_t bi = 0; bi < bases.size(); ++bi) {
    for (const auto& p : bases[bi].points) {
      // Binned by the stored (quantised) coordinates, which are what look-ups compare with.
      point_pos.push_back(QuantisedMm(p.p));
      // mm -> Q10.6: round(mm * 64); model coordinates are far inside +-512 mm.
      points.push_back({QCoordMm::FromDouble(p.p.x()).raw(), QCoordMm::FromDouble(p.p.y()).raw(),
                        QCoordMm::FromDouble(p.p.z()).raw(), uint16_t(bi)});
    }
    for (const auto& l : bases[bi].lines) {
      line_support.push_back(l.support);
      LineEntry e{};
      e.cx = QCoordMm::FromDouble(l.centre.x()).raw();
      e.cy = QCoordMm::FromDouble(l.centre.y()).raw();
      e.cz = QCoordMm::FromDouble(l.centre.z()).raw();
      // unit components -> Q2.14: round(v * 16384)
      e.vx = QUnit::FromDouble(l.direction.x()).raw();
      e.vy = QUnit::FromDouble(l.direction.y()).raw();
      e.vz = QUnit::FromDouble(l.direction.z()).raw();
      e.length = UQ<10, 6>::FromDouble(l.length).raw();  // mm -> unsigned Q10.6
      e.basis = uint16_t(bi);
      lines.push_back(e);
    }
  }
  const GridGeometry point_grid = MakeGrid(point_pos, options.point_bin_mm);
  const GridGeometry line_grid = MakeGrid(line_support, options.line_bin_mm);
  if (point_grid.bin_count() > kMaxTableBins || line_grid.bin_count() > kMaxTableBins)
    return Status::Error(StatusCode::kResourceExhausted, "hash grid has too many bins");
  std::vector<uint32_t> point_bin_of, line_bin_of, point_order, line_order;
  for (const auto& p : point_pos) point_bin_of.push_back(BinOf(point_grid, p));
  for (const auto& s : line_support) line_bin_of.push_back(BinOf(line_grid, s));
  const std::vector<uint32_t> point_offsets =
      SortByBin(point_bin_of, point_grid.bin_count(), &point_order, &rep.max_point_bin_entries);
  const std::vector<uint32_t> line_offsets =
      SortByBin(line_bin_of, line_grid.bin_count(), &line_order, &rep.max_line_bin_entries);
  std::vector<PointEntry> points_sorted(points.size());
  std::vector<LineEntry> lines_sorted(lines.size());
  for (size_t i = 0; i < points.size(); ++i) points_sorted[i] = points[point_order[i]];
  for (size_t i = 0; i < lines.size(); ++i) lines_sorted[i] = lines[line_order[i]];

  // Lay out the sections.
  TableHeader h{};
  std::memcpy(h.magic, kTableMagic, sizeof(kTableMagic));
  h.format_version = kTableFormatVersion;
  h.hash_function = uint8_t(hf);
  h.header_size = sizeof(TableHeader);
  h.n_models = uint32_t(models.size());
  h.n_bases = uint32_t(bases.size());
  h.n_point_entries = uint32_t(points.size());
  h.n_line_entries = uint32_t(lines.size());
  h.max_point_bin_entries = rep.max_point_bin_entries;
  h.max_line_bin_entries = rep.max_line_bin_entries;
  h.point_grid = point_grid;
  h.line_grid = line_grid;
  const BasisLimits& L = options.limits;
  h.min_point_line_mm = L.min_point_line_mm;
  h.max_point_line_mm = L.max_point_line_mm;
  h.min_line_angle_deg = L.min_line_angle_deg;
  h.max_line_distance_mm = L.max_line_distance_mm;
  h.min_point_spacing_mm = L.min_point_spacing_mm;
  h.max_point_spacing_mm = L.max_point_spacing_mm;
  h.min_triangle_height_mm = L.min_triangle_height_mm;
  SectionLayout layout(sizeof(TableHeader));
  layout.Place(&h.models, models.size() * sizeof(Model));
  layout.Place(&h.bases, bases.size() * sizeof(BasisRecord));
  layout.Place(&h.point_bins, point_offsets.size() * sizeof(uint32_t));
  layout.Place(&h.point_entries, points_sorted.size() * sizeof(PointEntry));
  layout.Place(&h.line_bins, line_offsets.size() * sizeof(uint32_t));
  layout.Place(&h.line_entries, lines_sorted.size() * sizeof(LineEntry));
  h.total_size = layout.total_size();

  std::vector<uint8_t> blob(layout.total_size(), 0);
  std::vector<BasisRecord> records;
  records.reserve(bases.size());
  for (const auto& b : bases) records.push_back(b.record);
  PutSection(blob, h.models, models.data(), models.size());
  PutSection(blob, h.bases, records.data(), records.size());
  PutSection(blob, h.point_bins, point_offsets.data(), point_offsets.size());
  PutSection(blob, h.point_entries, points_sorted.data(), points_sorted.size());
  PutSection(blob, h.line_bins, line_offsets.data(), line_offsets.size());
  PutSection(blob, h.line_entries, lines_sorted.data(), lines_sorted.size());
  SealBlob(blob, h);
  return blob;
}

}  // namespace sh
