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
  int group_first_half_edge[kMaxModelFaces] = {};
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

// Links each boundary half-edge of a merged face to the next one along the face outline, checks
// that every face has exactly one outline (no holes, no pinched vertices), and marks as corners
// the vertices where some outline turns.
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
    int first = -1, n_boundary = 0;
    for (int h = 0; h < mesh.n_half_edges; ++h) {
      if (topo.next_boundary[h] >= 0 && topo.group_of[topo.polygon_of[h]] == group) {
        if (first < 0) first = h;
        ++n_boundary;
      }
    }
    int loop_length = 0;
    int h = first;
    do {
      ++loop_length;
      h = topo.next_boundary[h];
    } while (h != first && loop_length <= n_boundary);
    if (first < 0 || loop_length != n_boundary) {
      return Status::Error(StatusCode::kInvalidArgument,
                           "%s: a face has a hole (more than one outline); not supported",
                           o.format);
    }
    topo.group_first_half_edge[group] = first;
    h = first;
    do {
      const int nh = topo.next_boundary[h];
      const Eigen::Vector3d& a = mesh.vertices[mesh.from(h)];
      const Eigen::Vector3d& v = mesh.vertices[mesh.from(nh)];
      const Eigen::Vector3d& b = mesh.vertices[ToVertex(mesh, topo, nh)];
      const Eigen::Vector3d in = v - a, out = b - v;
      // The outline turns at v unless it continues straight on: v within the planarity
      // tolerance of the line from a to b (the rounding of printed coordinates).
      const Eigen::Vector3d chord = b - a;
      const bool straight =
          in.dot(out) > 0 && in.cross(chord).norm() <= tolerance_mm * chord.norm();
      if (!straight) topo.is_corner[mesh.from(nh)] = true;
      h = nh;
    } while (h != first);
  }
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
    ModelFace& face = model.faces[group];
    Eigen::Vector3d n = Eigen::Vector3d::Zero();
    for (int f = 0; f < mesh.n_polygons; ++f) {
      if (topo.group_of[f] == group) n += topo.newell[f];
    }
    n.normalize();
    const int first = topo.group_first_half_edge[group];
    int h = first;
    double offset_sum = 0;
    do {
      const int c = topo.corner_index[mesh.from(h)];
      if (c >= 0) {
        if (face.n_vertices >= kMaxFaceVertices) {
          return Status::Error(StatusCode::kResourceExhausted,
                               "%s: a face has more than %d corners", o.format, kMaxFaceVertices);
        }
        face.vertices[face.n_vertices++] = static_cast<uint8_t>(c);
        offset_sum += n.dot(mesh.vertices[mesh.from(h)]);
      }
      h = topo.next_boundary[h];
    } while (h != first);
    if (face.n_vertices < 3) {
      return Status::Error(StatusCode::kInvalidArgument, "%s: a face has fewer than 3 corners",
                           o.format);
    }
    for (int k = 0; k < 3; ++k) face.normal[k] = static_cast<float>(n[k]);
    face.offset_mm = static_cast<float>(offset_sum / face.n_vertices);
  }

  // Edges: outline pieces between consecutive corners, recorded once from the lower-numbered
  // face, oriented as in face0's counter-clockwise outline.
  int n_edges = 0;
  for (int group = 0; group < topo.n_groups; ++group) {
    const int first = topo.group_first_half_edge[group];
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
        if (n_edges >= kMaxModelEdges) {
          return Status::Error(StatusCode::kResourceExhausted, "%s: more than %d edges", o.format,
                               kMaxModelEdges);
        }
        ModelEdge& e = model.edges[n_edges++];
        e.a = static_cast<uint8_t>(a);
        e.b = static_cast<uint8_t>(b);
        e.face0 = static_cast<uint8_t>(group);
        e.face1 = static_cast<uint8_t>(other);
      }
      h = g;
    } while (h != start);
  }
  model.n_edges = static_cast<uint16_t>(n_edges);
  return model;
}

}  // namespace sh
