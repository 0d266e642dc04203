#include "recog/model/mesh_model.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstring>

namespace sh {
namespace {

// ---------------------------------------------------------------------------------------------
// Topology and merging.

struct Topology {
  int polygon_of[kMaxObjHalfEdges] = {};
  int twin[kMaxObjHalfEdges] = {};
  Eigen::Vector3d newell[kMaxObjPolygons];  // |newell| = 2 * area, direction = normal
  double offset[kMaxObjPolygons] = {};
  int parent[kMaxObjPolygons] = {};  // union-find over polygons
  int group_of[kMaxObjPolygons] = {};
  int n_groups = 0;
  int corner_index[kMaxObjVertices] = {};  // -1 if the vertex is not a corner
  bool is_corner[kMaxObjVertices] = {};
  int next_boundary[kMaxObjHalfEdges] = {};  // -1 for interior half-edges
  bool smooth[kMaxObjHalfEdges] = {};        // between facets of a curved surface
  // Each face's outlines: the outer one (counter-clockwise about the face normal), then its holes
  // (clockwise), each as one of its boundary half-edges.
  int loop_first[kMaxModelFaces][1 + kMaxFaceHoles] = {};
  int n_loops[kMaxModelFaces] = {};
};

int Find(int* parent, int i) {
  while (parent[i] != i) i = parent[i] = parent[parent[i]];
  return i;
}

int ToVertex(const PolygonMesh& mesh, const Topology& topo, int h) {
  return mesh.from(mesh.next_in_polygon(h, topo.polygon_of[h]));
}

constexpr double kPi = 3.14159265358979323846;

struct OffPlane {
  double distance_mm = 0;
  int vertex = 0;  // 0-based OBJ vertex index
};

// The vertex of polygon f farthest from the plane normal . x = offset.
OffPlane FarthestOffPlane(const PolygonMesh& mesh, int f, const Eigen::Vector3d& normal,
                          double offset) {
  OffPlane off;
  for (int h = mesh.polygon_start[f]; h < mesh.polygon_start[f + 1]; ++h) {
    const double d = std::abs(normal.dot(mesh.vertices[mesh.from(h)]) - offset);
    if (d > off.distance_mm) off = {d, mesh.from(h)};
  }
  return off;
}

// Polygons merged pairwise can still drift out of one plane (a finely faceted curve): every
// vertex of a merged face must lie within the tolerance of the face's plane.
Status CheckMergedFacesFlat(const PolygonMesh& mesh, double tolerance_mm, const MeshModelOptions& o,
                            const Topology& topo) {
  for (int group = 0; group < topo.n_groups; ++group) {
    Eigen::Vector3d n = Eigen::Vector3d::Zero();
    double offset_sum = 0;
    int n_vertices = 0, first = -1;
    for (int f = 0; f < mesh.n_polygons; ++f) {
      if (topo.group_of[f] != group) continue;
      n += topo.newell[f];
      if (first < 0) first = f;
    }
    n.normalize();
    for (int f = 0; f < mesh.n_polygons; ++f) {
      if (topo.group_of[f] != group) continue;
      for (int h = mesh.polygon_start[f]; h < mesh.polygon_start[f + 1]; ++h) {
        offset_sum += n.dot(mesh.vertices[mesh.from(h)]);
        ++n_vertices;
      }
    }
    const double offset = offset_sum / n_vertices;
    for (int f = 0; f < mesh.n_polygons; ++f) {
      if (topo.group_of[f] != group) continue;
      const OffPlane off = FarthestOffPlane(mesh, f, n, offset);
      if (off.distance_mm > tolerance_mm) {
        return Status::Error(StatusCode::kInvalidArgument,
                             "%s %ss %d and %d: the face they form together is not planar: "
                             "vertex %d lies %.3g mm off its plane (tolerance %.3g mm)",
                             o.format, o.polygon_word, mesh.polygon_source[first],
                             mesh.polygon_source[f], off.vertex + 1, off.distance_mm, tolerance_mm);
      }
    }
  }
  return Status::Ok();
}

Status BuildTopology(const PolygonMesh& mesh, double tolerance_mm, const MeshModelOptions& o,
                     Topology& topo) {
  for (int f = 0; f < mesh.n_polygons; ++f) {
    Eigen::Vector3d n = Eigen::Vector3d::Zero();
    Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
    for (int h = mesh.polygon_start[f]; h < mesh.polygon_start[f + 1]; ++h) {
      topo.polygon_of[h] = f;
      const Eigen::Vector3d& a = mesh.vertices[mesh.from(h)];
      const Eigen::Vector3d& b = mesh.vertices[mesh.from(mesh.next_in_polygon(h, f))];
      if (mesh.from(h) == mesh.from(mesh.next_in_polygon(h, f))) {
        return Status::Error(StatusCode::kInvalidArgument, "%s %s %d: face repeats vertex %d",
                             o.format, o.polygon_word, mesh.polygon_source[f], mesh.from(h) + 1);
      }
      n += a.cross(b);  // Newell's method: robust for non-convex planar polygons
      centroid += a;
    }
    centroid /= mesh.size(f);
    if (n.norm() < 1e-12 * tolerance_mm * tolerance_mm || !std::isfinite(n.norm())) {
      return Status::Error(StatusCode::kInvalidArgument, "%s %s %d: face has zero area", o.format,
                           o.polygon_word, mesh.polygon_source[f]);
    }
    topo.newell[f] = n;
    const Eigen::Vector3d unit = n.normalized();
    topo.offset[f] = unit.dot(centroid);
    const OffPlane off = FarthestOffPlane(mesh, f, unit, topo.offset[f]);
    if (off.distance_mm > tolerance_mm) {
      return Status::Error(StatusCode::kInvalidArgument,
                           "%s %s %d: face is not planar: vertex %d lies %.3g mm off its plane "
                           "(tolerance %.3g mm)",
                           o.format, o.polygon_word, mesh.polygon_source[f], off.vertex + 1,
                           off.distance_mm, tolerance_mm);
    }
    topo.parent[f] = f;
  }

  // Twins: a closed, consistently wound 2-manifold has exactly one b->a for every a->b.
  for (int h = 0; h < mesh.n_half_edges; ++h) {
    const int a = mesh.from(h), b = ToVertex(mesh, topo, h);
    int twin = -1;
    for (int g = 0; g < mesh.n_half_edges; ++g) {
      if (g == h) continue;
      const int c = mesh.from(g), d = ToVertex(mesh, topo, g);
      if (c == a && d == b) {
        return Status::Error(StatusCode::kInvalidArgument,
                             "%s: edge %d-%d is used twice in the same direction (non-manifold "
                             "or inconsistent winding)",
                             o.format, a + 1, b + 1);
      }
      if (c == b && d == a) {
        if (twin >= 0) {
          return Status::Error(StatusCode::kInvalidArgument,
                               "%s: edge %d-%d is shared by more than two faces (non-manifold)",
                               o.format, a + 1, b + 1);
        }
        twin = g;
      }
    }
    if (twin < 0) {
      return Status::Error(StatusCode::kInvalidArgument,
                           "%s: edge %d-%d belongs to one face only (surface not closed)", o.format,
                           a + 1, b + 1);
    }
    topo.twin[h] = twin;
  }

  // Merge adjacent polygons that lie in one plane; a fold too shallow to be an edge is a face
  // that should be flat and is not.
  for (int h = 0; h < mesh.n_half_edges; ++h) {
    const int f = topo.polygon_of[h], g = topo.polygon_of[topo.twin[h]];
    if (f >= g) continue;  // each shared edge once
    const Eigen::Vector3d nf = topo.newell[f].normalized(), ng = topo.newell[g].normalized();
    OffPlane off = FarthestOffPlane(mesh, g, nf, topo.offset[f]);
    int plane_of = f;
    const OffPlane off_g = FarthestOffPlane(mesh, f, ng, topo.offset[g]);
    if (off_g.distance_mm > off.distance_mm) {
      off = off_g;
      plane_of = g;
    }
    if (nf.dot(ng) > 0.0 && off.distance_mm <= tolerance_mm) {
      topo.parent[Find(topo.parent, f)] = Find(topo.parent, g);
      continue;
    }
    const double fold_deg = std::acos(std::clamp(nf.dot(ng), -1.0, 1.0)) * 180.0 / kPi;
    if (fold_deg < o.smooth_below_deg) {
      // Facets of a curved surface: each stays a face of its own, joined by a smooth edge.
      topo.smooth[h] = topo.smooth[topo.twin[h]] = true;
      continue;
    }
    if (fold_deg < o.min_edge_angle_deg && o.edge_angle_hint != nullptr) {
      // Short: the path comes in front, and messages hold 160 characters.
      return Status::Error(StatusCode::kInvalidArgument,
                           "%s %ss %d and %d bend by %.2g degrees, %s", o.format, o.polygon_word,
                           mesh.polygon_source[f], mesh.polygon_source[g], fold_deg,
                           o.edge_angle_hint);
    }
    if (fold_deg < o.min_edge_angle_deg) {
      return Status::Error(
          StatusCode::kInvalidArgument,
          "%s %ss %d and %d: adjacent faces bend by only %.2g degrees at edge %d-%d: vertex %d "
          "lies %.3g mm off the plane of the face at %s %d (a flat face must be flat within %.3g "
          "mm, an edge must bend by at least %g degrees)",
          o.format, o.polygon_word, mesh.polygon_source[f], mesh.polygon_source[g], fold_deg,
          mesh.from(h) + 1, ToVertex(mesh, topo, h) + 1, off.vertex + 1, off.distance_mm,
          o.polygon_word, mesh.polygon_source[plane_of], tolerance_mm, o.min_edge_angle_deg);
    }
  }
  int root_group[kMaxObjPolygons];
  for (int f = 0; f < mesh.n_polygons; ++f) root_group[f] = -1;
  for (int f = 0; f < mesh.n_polygons; ++f) {
    const int r = Find(topo.parent, f);
    if (root_group[r] < 0) {
      if (topo.n_groups >= kMaxModelFaces) {
        return Status::Error(StatusCode::kResourceExhausted,
                             "%s: more than %d faces after merging coplanar polygons", o.format,
                             kMaxModelFaces);
      }
      root_group[r] = topo.n_groups++;
    }
    topo.group_of[f] = root_group[r];
  }
  return CheckMergedFacesFlat(mesh, tolerance_mm, o, topo);
}

bool IsBoundary(const Topology& topo, int h) {
  return topo.group_of[topo.polygon_of[h]] != topo.group_of[topo.polygon_of[topo.twin[h]]];
}

// The sum of a face's polygons' Newell vectors: twice its area along its outward normal.
Eigen::Vector3d GroupNewell(const PolygonMesh& mesh, const Topology& topo, int group) {
  Eigen::Vector3d n = Eigen::Vector3d::Zero();
  for (int f = 0; f < mesh.n_polygons; ++f) {
    if (topo.group_of[f] == group) n += topo.newell[f];
  }
  return n;
}

// Twice the signed area of the outline through half-edge `first`, along `normal`: positive for
// an outer outline, negative for a hole's.
double LoopArea2(const PolygonMesh& mesh, const Topology& topo, int first,
                 const Eigen::Vector3d& normal) {
  Eigen::Vector3d n = Eigen::Vector3d::Zero();
  int h = first;
  do {
    const int nh = topo.next_boundary[h];
    n += mesh.vertices[mesh.from(h)].cross(mesh.vertices[mesh.from(nh)]);
    h = nh;
  } while (h != first);
  return n.dot(normal);
}

// The outlines of face `group` (topo.loop_first, outer first): exactly one outer outline and at
// most kMaxFaceHoles holes.
Status FindLoops(const PolygonMesh& mesh, const MeshModelOptions& o, int group, Topology& topo) {
  bool seen[kMaxObjHalfEdges] = {};
  const Eigen::Vector3d normal = GroupNewell(mesh, topo, group);
  int outer = -1, holes = 0;
  int hole_first[kMaxFaceHoles];
  for (int start = 0; start < mesh.n_half_edges; ++start) {
    if (seen[start] || topo.next_boundary[start] < 0 ||
        topo.group_of[topo.polygon_of[start]] != group) {
      continue;
    }
    int h = start;
    do {
      seen[h] = true;
      h = topo.next_boundary[h];
    } while (h != start && !seen[h]);
    if (h != start) {
      return Status::Error(StatusCode::kInternal, "%s: a face outline does not close", o.format);
    }
    if (LoopArea2(mesh, topo, start, normal) > 0) {
      if (outer >= 0) {
        return Status::Error(StatusCode::kInvalidArgument,
                             "%s: a face has two outer outlines (two faces touching in a plane)",
                             o.format);
      }
      outer = start;
    } else {
      if (holes >= kMaxFaceHoles) {
        return Status::Error(StatusCode::kResourceExhausted, "%s: a face has more than %d holes",
                             o.format, kMaxFaceHoles);
      }
      hole_first[holes++] = start;
    }
  }
  if (outer < 0) {
    return Status::Error(StatusCode::kInvalidArgument, "%s: a face has no outer outline", o.format);
  }
  topo.loop_first[group][0] = outer;
  for (int k = 0; k < holes; ++k) topo.loop_first[group][1 + k] = hole_first[k];
  topo.n_loops[group] = 1 + holes;
  return Status::Ok();
}

// Marks as corners the vertices where the outline through `first` turns.
void MarkTurningVertices(const PolygonMesh& mesh, double tolerance_mm, Topology& topo, int first) {
  int h = first;
  do {
    const int nh = topo.next_boundary[h];
    const Eigen::Vector3d& a = mesh.vertices[mesh.from(h)];
    const Eigen::Vector3d& v = mesh.vertices[mesh.from(nh)];
    const Eigen::Vector3d& b = mesh.vertices[ToVertex(mesh, topo, nh)];
    const Eigen::Vector3d in = v - a, out = b - v;
    // The outline turns at v unless it continues straight on: v within the planarity
    // tolerance of the line from a to b (the rounding of printed coordinates).
    const Eigen::Vector3d chord = b - a;
    const bool straight = in.dot(out) > 0 && in.cross(chord).norm() <= tolerance_mm * chord.norm();
    if (!straight) topo.is_corner[mesh.from(nh)] = true;
    h = nh;
  } while (h != first);
}

// Links each boundary half-edge of a merged face to the next one along the face outline (no
// pinched vertices), finds each face's outer outline and holes, and marks as corners the
// vertices where some outline turns.
Status TraceOutlines(const PolygonMesh& mesh, double tolerance_mm, const MeshModelOptions& o,
                     Topology& topo) {
  for (int h = 0; h < mesh.n_half_edges; ++h) {
    topo.next_boundary[h] = -1;
    if (!IsBoundary(topo, h)) continue;
    const int group = topo.group_of[topo.polygon_of[h]];
    const int b = ToVertex(mesh, topo, h);
    for (int g = 0; g < mesh.n_half_edges; ++g) {
      if (mesh.from(g) != b || !IsBoundary(topo, g) || topo.group_of[topo.polygon_of[g]] != group)
        continue;
      if (topo.next_boundary[h] >= 0) {
        return Status::Error(StatusCode::kInvalidArgument,
                             "%s: face outline passes twice through vertex %d (pinched face)",
                             o.format, b + 1);
      }
      topo.next_boundary[h] = g;
    }
    if (topo.next_boundary[h] < 0) {
      return Status::Error(StatusCode::kInternal, "%s: open face outline at vertex %d", o.format,
                           b + 1);
    }
  }
  for (int group = 0; group < topo.n_groups; ++group) {
    SH_RETURN_IF_ERROR(FindLoops(mesh, o, group, topo));
    for (int l = 0; l < topo.n_loops[group]; ++l) {
      MarkTurningVertices(mesh, tolerance_mm, topo, topo.loop_first[group][l]);
    }
  }
  return Status::Ok();
}

// The corners along the outline through `first`, in order, appended to `out` (at most `most`),
// and the sum of their offsets along `normal` added to `offset_sum`.
Status LoopCorners(const PolygonMesh& mesh, const MeshModelOptions& o, const Topology& topo,
                   int first, const Eigen::Vector3d& normal, uint8_t* out, int* n, int most,
                   double* offset_sum) {
  int h = first;
  do {
    const int c = topo.corner_index[mesh.from(h)];
    if (c >= 0) {
      *offset_sum += normal.dot(mesh.vertices[mesh.from(h)]);
      if (*n >= most) {
        return Status::Error(StatusCode::kResourceExhausted, "%s: a face has more than %d corners",
                             o.format, kMaxFaceVertices);
      }
      out[(*n)++] = static_cast<uint8_t>(c);
    }
    h = topo.next_boundary[h];
  } while (h != first);
  return Status::Ok();
}

// Whether the open segments p-q and a-b cross or touch, in the face's plane (projected along
// its dominant normal axis `drop`). Segments sharing an end point do not count.
bool SegmentsMeet(const Model& m, int drop, int p, int q, int a, int b) {
  if (p == a || p == b || q == a || q == b) return false;
  const int u = drop == 0 ? 1 : 0, v = drop == 2 ? 1 : 2;
  auto at = [&](int c) { return Eigen::Vector2d(m.corners_mm[c][u], m.corners_mm[c][v]); };
  auto side = [](const Eigen::Vector2d& o, const Eigen::Vector2d& x, const Eigen::Vector2d& y) {
    const Eigen::Vector2d d1 = x - o, d2 = y - o;
    return d1.x() * d2.y() - d1.y() * d2.x();
  };
  const Eigen::Vector2d P = at(p), Q = at(q), A = at(a), B = at(b);
  const double d1 = side(P, Q, A), d2 = side(P, Q, B), d3 = side(A, B, P), d4 = side(A, B, Q);
  return (d1 <= 0) != (d2 <= 0) && (d3 <= 0) != (d4 <= 0);
}

// Whether the bridge p-q crosses an edge of the face's outlines (`loops`, as corner lists).
bool BridgeCrosses(const Model& m, int drop, int p, int q, const uint8_t* const* loops,
                   const int* sizes, int n_loops) {
  for (int l = 0; l < n_loops; ++l) {
    for (int k = 0, j = sizes[l] - 1; k < sizes[l]; j = k++) {
      if (SegmentsMeet(m, drop, p, q, loops[l][j], loops[l][k])) return true;
    }
  }
  return false;
}

// Face `group` of `model` from its outlines: the outer outline's corners, counter-clockwise from
// outside, with each hole spliced in along the shortest bridge between an outline corner and a
// hole corner that crosses no outline: ... p, h_j, h_j+1, ..., h_j-1, h_j, p, ... The bridge's two
// passes cancel in every even-odd polygon test (PointInFace, the silhouettes, the renderers), and
// edges come from the outlines, so the bridge is no edge.
Status BuildFace(const PolygonMesh& mesh, const MeshModelOptions& o, const Topology& topo,
                 int group, const Model& model, ModelFace& face) {
  const Eigen::Vector3d n = GroupNewell(mesh, topo, group).normalized();
  uint8_t loops[1 + kMaxFaceHoles][kMaxFaceVertices];
  int sizes[1 + kMaxFaceHoles] = {};
  const uint8_t* loop_ptrs[1 + kMaxFaceHoles];
  double offset_sum = 0;
  int n_corners = 0;
  for (int l = 0; l < topo.n_loops[group]; ++l) {
    SH_RETURN_IF_ERROR(LoopCorners(mesh, o, topo, topo.loop_first[group][l], n, loops[l], &sizes[l],
                                   kMaxFaceVertices, &offset_sum));
    if (sizes[l] < 3) {
      return Status::Error(StatusCode::kInvalidArgument, "%s: a face %shas fewer than 3 corners",
                           o.format, l == 0 ? "" : "hole ");
    }
    n_corners += sizes[l];
    loop_ptrs[l] = loops[l];
  }
  const int drop = std::fabs(n.x()) >= std::fabs(n.y()) && std::fabs(n.x()) >= std::fabs(n.z())
                       ? 0
                       : (std::fabs(n.y()) >= std::fabs(n.z()) ? 1 : 2);
  uint8_t* out = face.vertices;
  int size = sizes[0];
  std::copy(loops[0], loops[0] + size, out);
  for (int l = 1; l < topo.n_loops[group]; ++l) {
    if (size + sizes[l] + 2 > kMaxFaceVertices) {
      return Status::Error(StatusCode::kResourceExhausted,
                           "%s: a face has more than %d corners (with two more per hole)", o.format,
                           kMaxFaceVertices);
    }
    int best_i = -1, best_j = -1;
    float best_d2 = 0;
    for (int i = 0; i < size; ++i) {
      // A corner the outline already passes twice (a bridge's end) is not used again.
      if (std::count(out, out + size, out[i]) > 1) continue;
      for (int j = 0; j < sizes[l]; ++j) {
        const float d2 = (model.corner(out[i]) - model.corner(loops[l][j])).squaredNorm();
        if (best_i >= 0 && d2 >= best_d2) continue;
        const uint8_t* current[1] = {out};
        if (BridgeCrosses(model, drop, out[i], loops[l][j], current, &size, 1) ||
            BridgeCrosses(model, drop, out[i], loops[l][j], loop_ptrs + 1, sizes + 1,
                          topo.n_loops[group] - 1)) {
          continue;
        }
        best_i = i, best_j = j, best_d2 = d2;
      }
    }
    if (best_i < 0) {
      return Status::Error(StatusCode::kInvalidArgument,
                           "%s: a face's hole cannot be joined to its outline", o.format);
    }
    // out[0..best_i], the hole from best_j round to best_j, out[best_i], out[best_i+1..].
    uint8_t spliced[kMaxFaceVertices];
    int k = 0;
    for (int i = 0; i <= best_i; ++i) spliced[k++] = out[i];
    for (int j = 0; j <= sizes[l]; ++j) spliced[k++] = loops[l][(best_j + j) % sizes[l]];
    for (int i = best_i; i < size; ++i) spliced[k++] = out[i];
    size = k;
    std::copy(spliced, spliced + size, out);
  }
  face.n_vertices = static_cast<uint8_t>(size);
  for (int k = 0; k < 3; ++k) face.normal[k] = static_cast<float>(n[k]);
  face.offset_mm = static_cast<float>(offset_sum / n_corners);
  return Status::Ok();
}

// The edges along the outline of face `group` through half-edge `first` that face `group` records
// (those towards a higher-numbered face), appended to model.edges.
Status AddOutlineEdges(const PolygonMesh& mesh, const MeshModelOptions& o, const Topology& topo,
                       int group, int first, Model& model, int* n_edges) {
  // Start the walk at a corner so every piece runs corner to corner.
  int start = first;
  while (topo.corner_index[mesh.from(start)] < 0) start = topo.next_boundary[start];
  int h = start;
  do {
    const int a = topo.corner_index[mesh.from(h)];
    const int other = topo.group_of[topo.polygon_of[topo.twin[h]]];
    int g = h;
    do {
      if (topo.group_of[topo.polygon_of[topo.twin[g]]] != other) {
        return Status::Error(StatusCode::kInternal,
                             "%s: neighbouring face changes between two corners", o.format);
      }
      g = topo.next_boundary[g];
    } while (topo.corner_index[mesh.from(g)] < 0);
    const int b = topo.corner_index[mesh.from(g)];
    if (group < other) {
      if (*n_edges >= kMaxModelEdges) {
        return Status::Error(StatusCode::kResourceExhausted, "%s: more than %d edges", o.format,
                             kMaxModelEdges);
      }
      ModelEdge& e = model.edges[(*n_edges)++];
      e.a = static_cast<uint8_t>(a);
      e.b = static_cast<uint8_t>(b);
      e.face0 = static_cast<uint8_t>(group);
      e.face1 = static_cast<uint8_t>(other);
      e.smooth = topo.smooth[h] ? 1 : 0;
    }
    h = g;
  } while (h != start);
  return Status::Ok();
}

}  // namespace

Result<Model> ModelFromMesh(const PolygonMesh& mesh, const char* name,
                            const MeshModelOptions& options) {
  const MeshModelOptions& o = options;
  if (mesh.n_polygons == 0) {
    return Status::Error(StatusCode::kInvalidArgument, "%s has no faces", options.format);
  }
  Eigen::Vector3d lo = mesh.vertices[0], hi = mesh.vertices[0];
  for (int i = 1; i < mesh.n_vertices; ++i) {
    lo = lo.cwiseMin(mesh.vertices[i]);
    hi = hi.cwiseMax(mesh.vertices[i]);
  }
  const double size_mm = (hi - lo).norm();
  if (size_mm > kMaxObjSizeMm || size_mm < kMinObjSizeMm) {
    return Status::Error(StatusCode::kOutOfRange,
                         "%s: the model is %.4g mm across; supported: %g..%g mm (%s)", o.format,
                         size_mm, kMinObjSizeMm, kMaxObjSizeMm, o.units_hint);
  }
  const double tolerance_mm = std::max(kObjPlanarityMm, kObjPlanarityRelative * size_mm);

  Topology topo;
  SH_RETURN_IF_ERROR(BuildTopology(mesh, tolerance_mm, options, topo));
  SH_RETURN_IF_ERROR(TraceOutlines(mesh, tolerance_mm, options, topo));

  // Positive enclosed volume <=> outward normals (counter-clockwise winding from outside).
  double volume6 = 0;
  for (int f = 0; f < mesh.n_polygons; ++f) {
    const Eigen::Vector3d& v0 = mesh.vertices[mesh.from(mesh.polygon_start[f])];
    for (int h = mesh.polygon_start[f] + 1; h + 1 < mesh.polygon_start[f + 1]; ++h) {
      volume6 += v0.dot(mesh.vertices[mesh.from(h)].cross(mesh.vertices[mesh.from(h + 1)]));
    }
  }
  if (!(volume6 > 0)) {
    return Status::Error(StatusCode::kInvalidArgument,
                         "%s: faces are wound clockwise seen from outside (inward normals)",
                         o.format);
  }

  Model model;
  if (name != nullptr) std::strncpy(model.name, name, kMaxModelNameLength);
  int n_corners = 0;
  for (int v = 0; v < mesh.n_vertices; ++v) {
    topo.corner_index[v] = -1;
    if (!topo.is_corner[v]) continue;
    if (n_corners >= kMaxModelCorners) {
      return Status::Error(StatusCode::kResourceExhausted, "%s: more than %d corners", o.format,
                           kMaxModelCorners);
    }
    topo.corner_index[v] = n_corners;
    for (int k = 0; k < 3; ++k)
      model.corners_mm[n_corners][k] = static_cast<float>(mesh.vertices[v][k]);
    ++n_corners;
  }
  model.n_corners = static_cast<uint16_t>(n_corners);
  model.n_faces = static_cast<uint16_t>(topo.n_groups);

  for (int group = 0; group < topo.n_groups; ++group) {
    SH_RETURN_IF_ERROR(BuildFace(mesh, o, topo, group, model, model.faces[group]));
  }

  // Edges: outline pieces between consecutive corners, recorded once from the lower-numbered
  // face, oriented as in face0's counter-clockwise outline (its holes' outlines included).
  int n_edges = 0;
  for (int group = 0; group < topo.n_groups; ++group) {
    for (int l = 0; l < topo.n_loops[group]; ++l) {
      SH_RETURN_IF_ERROR(
          AddOutlineEdges(mesh, o, topo, group, topo.loop_first[group][l], model, &n_edges));
    }
  }
  model.n_edges = static_cast<uint16_t>(n_edges);
  return model;
}

}  // namespace sh
