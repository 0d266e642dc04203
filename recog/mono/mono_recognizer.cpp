#include "recog/mono/mono_recognizer.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>

#include "recog/base/angles.hpp"
#include "recog/verify/inside_object.hpp"

namespace sh {
namespace {

// FNV-1a over the bytes of scene basis k and one of its hypotheses (MonoStats::votes_digest).
uint32_t DigestVote(uint32_t digest, uint32_t k, const AspectHypothesis& h) {
  uint32_t words[3] = {k, h.basis, 0};
  std::memcpy(&words[2], &h.vote, sizeof(float));
  for (const uint32_t w : words) {
    for (int byte = 0; byte < 4; ++byte) {
      digest = (digest ^ ((w >> (8 * byte)) & 0xffu)) * 16777619u;
    }
  }
  return digest;
}

bool DeadlinePassed(const Budget& b) {
  return b.deadline_ns != 0 && b.now_ns != nullptr && b.now_ns() >= b.deadline_ns;
}

}  // namespace

Status MonoRecognizer::Init(const ViewCamera& camera, const AspectTableView& table,
                            const RigidTransform* left_T_table, const MonoConfig& config) {
  initialised_ = false;
  if (!table.valid()) {
    return Status::Error(StatusCode::kInvalidArgument, "mono: no aspect table");
  }
  const CameraIntrinsics& cam = camera.intrinsics;
  if (!(cam.fx > 0 && cam.fy > 0) || cam.width <= 0 || cam.height <= 0) {
    return Status::Error(StatusCode::kInvalidArgument, "mono: invalid camera intrinsics");
  }
  if (!(config.min_basis_px > 1.0f && config.max_basis_px > config.min_basis_px) ||
      config.hypotheses_per_basis < 1 || config.hypotheses_per_basis > kMaxMonoHypotheses ||
      !(config.vote_threshold >= 0.0f && config.vote_threshold <= 2.0f) ||
      config.min_matched_features < 3) {
    return Status::Error(StatusCode::kInvalidArgument,
                         "mono: basis lengths, hypotheses (1..%d), threshold or minimum matches "
                         "out of range",
                         kMaxMonoHypotheses);
  }
  if (!(config.min_corner_isotropy >= 0.0f && config.min_corner_isotropy <= 0.5f)) {
    return Status::Error(StatusCode::kOutOfRange, "mono: corner isotropy %g outside [0, 0.5]",
                         static_cast<double>(config.min_corner_isotropy));
  }
  SH_RETURN_IF_ERROR(CheckVerifyConfig(config.verify));
  lent_voter_ready_ = false;  // its counters were laid out for the old table
  ahead_.Clear();
  SH_RETURN_IF_ERROR(voter_.Init(table, config.voter));
  for (uint32_t m = 0; m < table.model_count(); ++m) {
    SH_RETURN_IF_ERROR(ComputeStableFaces(table.model(m), 0.5f, &stable_[m]));
  }
  UseCamera(camera);
  table_ = table;
  config_ = config;
  has_table_ = false;
  SH_RETURN_IF_ERROR(SetTable(left_T_table));
  initialised_ = true;
  return Status::Ok();
}

Status MonoRecognizer::SetTable(const RigidTransform* left_T_table) {
  if (left_T_table != nullptr) {
    const RigidTransform cam_T_table = camera_.cam_T_left * *left_T_table;
    // The camera must look down at the table from above it.
    const RigidTransform table_T_cam = cam_T_table.Inverse();
    if (!(table_T_cam.t_mm.z() > 1.0f)) {
      return Status::Error(StatusCode::kInvalidArgument,
                           "mono: the camera is not above the table (height %.1f mm)",
                           table_T_cam.t_mm.z());
    }
    plane_.cam_T_table = cam_T_table;
  }
  has_table_ = left_T_table != nullptr;
  ComputeBasisKeys();
  voter_.SetBasisKeys(basis_key_);
  return Status::Ok();
}

Status MonoRecognizer::SetParallel(const ParallelFor& parallel, int threads) {
  if (!initialised_) {
    return Status::Error(StatusCode::kFailedPrecondition, "mono: Init() has not succeeded");
  }
  if (threads < 1) {
    return Status::Error(StatusCode::kInvalidArgument, "mono: %d threads", threads);
  }
  parallel_ = parallel;
  slots_used_ = parallel.concurrent() ? std::min(threads, kMonoEvaluationSlots) : 1;
  return Status::Ok();
}

Status MonoRecognizer::LendVoteCounters(uint8_t* bytes, size_t size) {
  lent_voter_ready_ = false;
  ahead_.Clear();
  if (!initialised_) {
    return Status::Error(StatusCode::kFailedPrecondition, "mono: Init() has not succeeded");
  }
  if (bytes == nullptr) return Status::Ok();
  SH_RETURN_IF_ERROR(lent_voter_.BorrowCounters(voter_, bytes, size));
  lent_voter_ready_ = true;
  return Status::Ok();
}

Status MonoRecognizer::SetCamera(const ViewCamera& camera) {
  if (!initialised_) {
    return Status::Error(StatusCode::kFailedPrecondition, "mono: Init() has not succeeded");
  }
  const CameraIntrinsics& cam = camera.intrinsics;
  if (!(cam.fx > 0 && cam.fy > 0) || cam.width <= 0 || cam.height <= 0) {
    return Status::Error(StatusCode::kInvalidArgument, "mono: invalid camera intrinsics");
  }
  // The table stays where it is in the left camera's frame; SetTable puts it into the new
  // camera's frame (and refuses a camera under it, after which the old one is put back).
  const RigidTransform left_T_table = left_T_cam_ * plane_.cam_T_table;
  const ViewCamera before = camera_;
  UseCamera(camera);
  const Status s = SetTable(has_table_ ? &left_T_table : nullptr);
  if (!s.ok()) UseCamera(before);
  return s;
}

void MonoRecognizer::UseCamera(const ViewCamera& camera) {
  camera_ = camera;
  left_T_cam_ = camera.cam_T_left.Inverse();
  ideal_focal_px_ = static_cast<float>(std::sqrt(camera.intrinsics.fx * camera.intrinsics.fy));
}

// Table mode: an aspect is kept when its view direction is close to how some resting pose of
// its model is seen from the camera: the angle between the view and the table's up direction
// (in the model frame: minus the stable face's normal) within the range of elevations under
// which the camera sees the table, widened by the margin.
void MonoRecognizer::ComputeBasisKeys() {
  float min_elev = 0.0f, max_elev = 180.0f;
  if (has_table_) {
    const RigidTransform table_T_cam = plane_.cam_T_table.Inverse();
    const Eigen::Vector3f centre = table_T_cam.t_mm;
    min_elev = 180.0f;
    max_elev = 0.0f;
    const CameraIntrinsics& cam = camera_.intrinsics;
    for (int gy = 0; gy <= 8; ++gy) {
      for (int gx = 0; gx <= 8; ++gx) {
        const Eigen::Vector2d px(cam.width * gx / 8.0, cam.height * gy / 8.0);
        const Eigen::Vector3f ray = table_T_cam.R * PixelRay(cam, px).cast<float>();
        if (!(ray.z() < -1e-3f)) continue;  // does not meet the table
        // Object points from the table top to 80 mm above it.
        for (float height : {0.0f, 80.0f}) {
          if (!(centre.z() > height)) continue;
          const Eigen::Vector3f p = centre + (height - centre.z()) / ray.z() * ray;
          const Eigen::Vector3f to_camera = (centre - p).normalized();
          const float elev = std::acos(std::max(-1.0f, std::min(1.0f, to_camera.z()))) * kRadToDeg;
          min_elev = std::min(min_elev, elev);
          max_elev = std::max(max_elev, elev);
        }
      }
    }
    min_elev -= config_.aspect_view_margin_deg;
    max_elev += config_.aspect_view_margin_deg;
  }
  aspects_enabled_ = 0;
  for (uint32_t a = 0; a < table_.aspect_count(); ++a) {
    const AspectRecord& rec = table_.aspect(a);
    bool enabled = !has_table_;
    const StableFaces& faces = stable_[rec.model];
    const Eigen::Vector3f dir(rec.dir_model[0], rec.dir_model[1], rec.dir_model[2]);
    for (int f = 0; f < faces.count && !enabled; ++f) {
      const float c = dir.dot(-faces.faces[f].normal_model);
      const float angle = std::acos(std::max(-1.0f, std::min(1.0f, c))) * kRadToDeg;
      enabled = angle >= min_elev && angle <= max_elev;
    }
    aspects_enabled_ += enabled;
    for (uint32_t b = rec.first_basis; b < rec.first_basis + rec.n_bases; ++b) {
      basis_key_[b] = enabled ? AspectApparentSizeMm(rec, table_.basis(b)) : NAN;
    }
  }
  // Highest point of a resting model above the table; largest distance of a corner from its
  // model's centroid.
  max_object_height_mm_ = 0;
  max_model_radius_mm_ = 0;
  for (uint32_t m = 0; m < table_.model_count(); ++m) {
    const Model& model = table_.model(m);
    const Eigen::Vector3f centroid = ModelCentroid(model);
    for (int i = 0; i < model.n_corners; ++i) {
      max_model_radius_mm_ = std::max(max_model_radius_mm_, (model.corner(i) - centroid).norm());
    }
    for (int f = 0; f < stable_[m].count; ++f) {
      const StableFace& face = stable_[m].faces[f];
      for (int i = 0; i < model.n_corners; ++i) {
        max_object_height_mm_ = std::max(max_object_height_mm_,
                                         face.offset_mm - face.normal_model.dot(model.corner(i)));
      }
    }
  }
}

// Table mode: the depths at which the scene basis can lie are those where its viewing ray runs
// between the table top and the highest resting object; at those depths a model basis of key k
// appears ideal_focal * k / depth pixels large.
void MonoRecognizer::KeyRange(const Frame2d& frame, VoteRequest* request) const {
  request->key_lo = -INFINITY;
  request->key_hi = INFINITY;
  if (!has_table_) return;
  const RigidTransform table_T_cam = plane_.cam_T_table.Inverse();
  const Eigen::Vector3f ray =
      table_T_cam.R *
      Eigen::Vector3f(frame.origin.x() / ideal_focal_px_, frame.origin.y() / ideal_focal_px_, 1.0f)
          .normalized();
  const float height = table_T_cam.t_mm.z();
  if (!(ray.z() < -1e-3f)) {
    request->key_lo = request->key_hi = NAN;  // above the horizon: nothing can rest there
    return;
  }
  const float near = std::max(1.0f, (height - max_object_height_mm_) / -ray.z());
  const float far = height / -ray.z();
  const float size_px = std::sqrt(std::fabs(frame.axes.determinant()));
  request->key_lo = size_px * near / ideal_focal_px_ * (1.0f - config_.max_scale_error);
  request->key_hi = size_px * far / ideal_focal_px_ * (1.0f + config_.max_scale_error);
  // An object's features lie within its diameter of any of its corners.
  request->reach = 2.0f * max_model_radius_mm_ * ideal_focal_px_ / near;
}

bool MonoRecognizer::CornerMayBase(int i) const {
  return i >= static_cast<int>(features_->corners.size()) ||
         features_->corners[static_cast<size_t>(i)].isotropy >= config_.min_corner_isotropy;
}

Status MonoRecognizer::PrepareScene(const ImageFeatures& f, const FeatureMask* ignore) {
  const CameraIntrinsics& cam = camera_.intrinsics;
  if (f.edges.edge.width != cam.width || f.edges.edge.height != cam.height) {
    return Status::Error(StatusCode::kInvalidArgument,
                         "mono: features of a %dx%d image, the camera is %dx%d", f.edges.edge.width,
                         f.edges.edge.height, cam.width, cam.height);
  }
  features_ = &f;
  n_corners_ = static_cast<int>(f.corners.size());
  n_lines_ = static_cast<int>(f.lines.size());
  for (int i = 0; i < n_corners_; ++i) {
    const Corner2D& c = f.corners[i];
    pose_corners_[i].px = {c.x_px, c.y_px};
    const Eigen::Vector2d n = UndistortPixel(cam, {c.x_px, c.y_px});
    ideal_points_[i].xy = ideal_focal_px_ * n.cast<float>();
    corner_active_[i] = CornerMayBase(i) ? 1 : 0;
  }
  for (int i = 0; i < n_lines_; ++i) {
    const Line2D& l = f.lines[i];
    PoseLine& p = pose_lines_[i];
    p.normal = {std::sin(l.theta_rad), std::cos(l.theta_rad)};
    p.rho = l.rho_px;
    p.dir = {l.dir_x, l.dir_y};
    p.t0 = INFINITY;
    p.t1 = -INFINITY;
    for (const Segment2D& s : l.segments) {
      for (const Eigen::Vector2f& e : {Eigen::Vector2f(s.x0, s.y0), Eigen::Vector2f(s.x1, s.y1)}) {
        const float t = p.dir.dot(e);
        p.t0 = std::min(p.t0, t);
        p.t1 = std::max(p.t1, t);
      }
    }
    line_active_[i] = 1;
    SceneLine2d& ideal = ideal_lines_[i];
    if (!(p.t1 > p.t0)) {
      line_active_[i] = 0;  // no support: cannot be matched or voted with
      continue;
    }
    // The ideal line through the undistorted ends of the support.
    const Eigen::Vector2f foot = p.rho * p.normal;
    const Eigen::Vector2f ea = foot + p.t0 * p.dir, eb = foot + p.t1 * p.dir;
    const Eigen::Vector2f ia =
        ideal_focal_px_ * UndistortPixel(cam, ea.cast<double>()).cast<float>();
    const Eigen::Vector2f ib =
        ideal_focal_px_ * UndistortPixel(cam, eb.cast<double>()).cast<float>();
    const float len = (ib - ia).norm();
    if (!(len > 1e-3f)) {
      line_active_[i] = 0;
      continue;
    }
    ideal.point = ia;
    ideal.dir = (ib - ia) / len;
    ideal.t0 = 0;
    ideal.t1 = len;
    // A line whose support lies within a hidden (convex) region belongs to what hides it.
    if (ignore != nullptr && ignore->Hides(ea.x(), ea.y()) && ignore->Hides(eb.x(), eb.y())) {
      line_active_[i] = 0;
    }
  }
  AddJunctionCorners();
  if (ignore != nullptr) {
    for (int i = 0; i < n_corners_; ++i) {
      if (ignore->Hides(pose_corners_[i].px.x(), pose_corners_[i].px.y())) corner_active_[i] = 0;
    }
  }
  return Status::Ok();
}

// Corners where two detected lines end at a common point (L- and Y-junctions of an object's
// edges). On low-contrast objects the corner detector misses many of these while the lines are
// found; their intersection is also the better estimate of the vertex.
void MonoRecognizer::AddJunctionCorners() {
  if (!config_.junction_corners) return;
  const CameraIntrinsics& cam = camera_.intrinsics;
  const float gap = config_.junction_gap_px;
  const float min_sin = std::sin(config_.match.min_corner_angle_deg * 3.14159265f / 180.0f);
  const int n_detected = n_corners_;
  for (int a = 0; a < n_lines_; ++a) {
    if (!line_active_[a]) continue;
    const PoseLine& la = pose_lines_[a];
    for (int b = a + 1; b < n_lines_; ++b) {
      if (!line_active_[b]) continue;
      const PoseLine& lb = pose_lines_[b];
      const float cross = la.normal.x() * lb.normal.y() - la.normal.y() * lb.normal.x();
      if (!(std::fabs(cross) >= min_sin)) continue;  // nearly parallel
      // normal_a . p = rho_a and normal_b . p = rho_b.
      const Eigen::Vector2f p((la.rho * lb.normal.y() - lb.rho * la.normal.y()) / cross,
                              (lb.rho * la.normal.x() - la.rho * lb.normal.x()) / cross);
      if (!(p.x() >= 0 && p.y() >= 0 && p.x() < cam.width && p.y() < cam.height)) continue;
      // Both supports must end at p.
      bool ends = true;
      for (const PoseLine* l : {&la, &lb}) {
        const float t = l->dir.dot(p);
        ends = ends && (std::fabs(t - l->t0) <= gap || std::fabs(t - l->t1) <= gap);
      }
      if (!ends) continue;
      bool known = false;
      for (int k = 0; k < n_corners_ && !known; ++k) {
        known = (pose_corners_[k].px - p).squaredNorm() <= 16.0f;  // within 4 px
      }
      if (known || n_corners_ == static_cast<int>(kMaxCorners2d)) continue;
      pose_corners_[n_corners_].px = p;
      ideal_points_[n_corners_].xy =
          ideal_focal_px_ * UndistortPixel(cam, p.cast<double>()).cast<float>();
      corner_active_[n_corners_] = 1;
      ++n_corners_;
    }
  }
  junction_corners_ = n_corners_ - n_detected;
}

void MonoRecognizer::GenerateBases() {
  n_candidates_ = 0;
  const bool affine = table_.basis_kind() == AspectBasisKind::kAffine;
  const float min2 = config_.min_basis_px * config_.min_basis_px;
  const float max2 = config_.max_basis_px * config_.max_basis_px;
  auto length_ok = [&](int i, int j) {
    const float d2 = (ideal_points_[i].xy - ideal_points_[j].xy).squaredNorm();
    return d2 >= min2 && d2 <= max2;
  };
  // Corners on each line (distorted image, where both were detected).
  for (int l = 0; l < n_lines_; ++l) {
    n_line_corners_[l] = 0;
    if (!line_active_[l]) continue;
    const PoseLine& line = pose_lines_[l];
    for (int k = 0; k < n_corners_ && n_line_corners_[l] < kMaxLineCorners; ++k) {
      const Eigen::Vector2f& px = pose_corners_[k].px;
      if (!(std::fabs(line.normal.dot(px) - line.rho) <= config_.corner_line_distance_px)) continue;
      const float t = line.dir.dot(px);
      if (t < line.t0 - config_.corner_line_margin_px ||
          t > line.t1 + config_.corner_line_margin_px) {
        continue;
      }
      line_corners_[l][n_line_corners_[l]++] = static_cast<uint16_t>(k);
    }
  }
  // Coverage of the stretch between two corners by the line's segments, in [0, 1].
  auto coverage = [&](int l, int i, int j) {
    const PoseLine& line = pose_lines_[l];
    float ta = line.dir.dot(pose_corners_[i].px), tb = line.dir.dot(pose_corners_[j].px);
    if (ta > tb) std::swap(ta, tb);
    if (!(tb - ta > 1e-3f)) return 0.0f;
    float covered = 0;
    for (const Segment2D& s : features_->lines[l].segments) {
      float s0 = line.dir.dot(Eigen::Vector2f(s.x0, s.y0));
      float s1 = line.dir.dot(Eigen::Vector2f(s.x1, s.y1));
      if (s0 > s1) std::swap(s0, s1);
      covered += std::max(0.0f, std::min(tb, s1) - std::max(ta, s0));
    }
    return std::min(1.0f, covered / (tb - ta));
  };
  auto push = [&](int a, int b, int c, float score) {
    if (n_candidates_ == kMaxMonoSceneBases) return;
    SceneBasis2d& s = candidates_[n_candidates_++];
    s.corners[0] = static_cast<uint16_t>(a);
    s.corners[1] = static_cast<uint16_t>(b);
    s.corners[2] = static_cast<uint16_t>(c < 0 ? 0 : c);
    s.score = score;
  };
  // Lines through each corner: object corners are junctions of two or more edges, most corners
  // of shadows and texture lie on one line or none.
  uint8_t lines_at[kMaxCorners2d] = {};
  for (int l = 0; l < n_lines_; ++l) {
    for (int p = 0; p < n_line_corners_[l]; ++p) {
      uint8_t& n = lines_at[line_corners_[l][p]];
      if (n < 255) ++n;
    }
  }
  // Connected pairs: corners joined by a line, scored by how much of the stretch between them
  // is edge-supported and whether both ends are junctions, longer bases first among equals
  // (they fix the frame better).
  for (int l = 0; l < n_lines_; ++l) {
    for (int p = 0; p < n_line_corners_[l]; ++p) {
      for (int q = p + 1; q < n_line_corners_[l]; ++q) {
        const int i = line_corners_[l][p], j = line_corners_[l][q];
        if (!length_ok(i, j)) continue;
        const float cov = coverage(l, i, j);
        if (cov < 0.5f) continue;
        const float len = (ideal_points_[i].xy - ideal_points_[j].xy).norm();
        const float junctions = (lines_at[i] >= 2 ? 1.0f : 0.0f) + (lines_at[j] >= 2 ? 1.0f : 0.0f);
        const float score = 2.0f + junctions + cov + 0.001f * len;
        if (!affine) {
          push(std::min(i, j), std::max(i, j), -1, score);
          continue;
        }
        // Affine: the pair plus a third corner joined to one of them by another line.
        for (int l2 = 0; l2 < n_lines_; ++l2) {
          if (l2 == l) continue;
          for (int r = 0; r < n_line_corners_[l2]; ++r) {
            const int k = line_corners_[l2][r];
            if (k == i || k == j) continue;
            bool shares = false;
            for (int s = 0; s < n_line_corners_[l2]; ++s) {
              shares = shares || line_corners_[l2][s] == j;
            }
            if (!shares || !length_ok(j, k)) continue;
            push(i, j, k, score + coverage(l2, j, k));
          }
        }
      }
    }
  }
  if (!config_.connected_bases_only && !affine) {
    for (int i = 0; i < n_corners_; ++i) {
      for (int j = i + 1; j < n_corners_; ++j) {
        if (!length_ok(i, j)) continue;
        push(i, j, -1, 0.001f * (ideal_points_[i].xy - ideal_points_[j].xy).norm());
      }
    }
  }
  std::sort(candidates_, candidates_ + n_candidates_,
            [](const SceneBasis2d& a, const SceneBasis2d& b) { return a.score > b.score; });
  // The same pair can be joined by two lines (or listed again among all pairs): keep the first.
  uint32_t kept = 0;
  for (uint32_t k = 0; k < n_candidates_; ++k) {
    bool duplicate = false;
    for (uint32_t q = kept; q-- > 0 && !duplicate;) {
      if (candidates_[q].score < candidates_[k].score - 3.0f) break;  // duplicates score alike
      duplicate = candidates_[q].corners[0] == candidates_[k].corners[0] &&
                  candidates_[q].corners[1] == candidates_[k].corners[1] &&
                  candidates_[q].corners[2] == candidates_[k].corners[2];
    }
    if (!duplicate) candidates_[kept++] = candidates_[k];
  }
  n_candidates_ = kept;
}

// Table mode: the resting pose a hypothesis starts from. The two first basis corners, whose
// model corners the basis names, lie on their viewing rays at their heights above the table for
// each stable face; the faces tried are those whose resting views match the aspect's view at
// the elevation under which the camera sees this part of the table, and the face whose corner
// distance on the table agrees best with the model's wins. When the two corners lie above each
// other (no heading from them), the hypothesis's own rotation, laid onto the face, gives it.
bool MonoRecognizer::RestingStart(const AspectBasis& basis, const AspectRecord& aspect,
                                  const Frame2d& frame, const RigidTransform& hypothesis,
                                  MonoStats* stats, RestingPose* out) const {
  const Model& model = table_.model(basis.model);
  const StableFaces& faces = stable_[basis.model];
  // The basis corners in ideal pixels (see SimilarityFrame, AffineFrame).
  Eigen::Vector2f p0, p1;
  if (table_.basis_kind() == AspectBasisKind::kAffine) {
    p0 = frame.origin - (frame.axes.col(0) + frame.axes.col(1)) / 3.0f;
    p1 = p0 + frame.axes.col(0);
  } else {
    p0 = frame.origin - 0.5f * frame.axes.col(0);
    p1 = frame.origin + 0.5f * frame.axes.col(0);
  }
  const Eigen::Vector3f ray0 =
      Eigen::Vector3f(p0.x() / ideal_focal_px_, p0.y() / ideal_focal_px_, 1);
  const Eigen::Vector3f ray1 =
      Eigen::Vector3f(p1.x() / ideal_focal_px_, p1.y() / ideal_focal_px_, 1);
  // Elevation of the view here: the angle between the direction to the camera and table up.
  const Eigen::Vector3f up_cam = plane_.cam_T_table.R.col(2);
  const float elevation =
      std::acos(std::max(-1.0f, std::min(1.0f, -(ray0 + ray1).normalized().dot(up_cam)))) *
      kRadToDeg;
  const Eigen::Vector3f dir(aspect.dir_model[0], aspect.dir_model[1], aspect.dir_model[2]);
  const Eigen::Vector3f a_model = model.corner(basis.corners[0]);
  const Eigen::Vector3f b_model = model.corner(basis.corners[1]);
  float best_cost = INFINITY;
  bool any_face = false;
  for (int f = 0; f < faces.count; ++f) {
    const float c = dir.dot(-faces.faces[f].normal_model);
    const float view_error =
        std::fabs(std::acos(std::max(-1.0f, std::min(1.0f, c))) * kRadToDeg - elevation);
    if (!(view_error <= config_.max_tilt_deg)) continue;
    any_face = true;
    RestingPose pose;
    float ratio = 1.0f, cost;
    if (RestingPoseFromCorners(plane_, faces, f, a_model, b_model, ray0, ray1,
                               0.25f * (b_model - a_model).norm(), &pose, &ratio)) {
      if (!(std::fabs(ratio - 1.0f) <= config_.max_depth_error)) continue;
      cost = std::fabs(ratio - 1.0f) + view_error / 90.0f;
    } else if (RestingPoseOnFace(plane_, faces, f, hypothesis, &pose)) {
      cost = 0.2f + view_error / 90.0f;
    } else {
      continue;
    }
    if (cost < best_cost) {
      best_cost = cost;
      *out = pose;
    }
  }
  if (!any_face) {
    ++stats->rejected_tilt;
    return false;
  }
  if (!(best_cost < INFINITY)) {
    ++stats->rejected_depth;
    return false;
  }
  return true;
}

bool MonoRecognizer::Evaluate(const AspectHypothesis& h, const Frame2d& scene_frame,
                              const Vector<RecognizedObject>& accepted, SlotScratch& scratch,
                              MonoStats* stats, Candidate* out) {
  const AspectBasis& basis = table_.basis(h.basis);
  const AspectRecord& aspect = table_.aspect(basis.aspect);
  const Model& model = table_.model(basis.model);
  const CameraIntrinsics& cam = camera_.intrinsics;
  Candidate& c = *out;
  c.model = basis.model;
  c.vote = h.vote;
  c.cam_T_model = PoseFromHypothesis(aspect, basis, scene_frame, ideal_focal_px_);
  if (has_table_) {
    if (!RestingStart(basis, aspect, scene_frame, c.cam_T_model, stats, &c.rest)) return false;
    c.cam_T_model = RestingTransform(plane_, stable_[basis.model], c.rest);
  }
  // Separation from the objects found so far (left-frame centres).
  const Eigen::Vector3f centre_left = left_T_cam_ * c.cam_T_model.t_mm;
  for (const RecognizedObject& o : accepted) {
    if ((o.cam_T_model.t_mm - centre_left).norm() < config_.min_object_separation_mm) {
      ++stats->rejected_overlap;
      return false;
    }
  }
  const ViewCamera own{cam, RigidTransform::Identity()};
  const PoseScene scene{pose_corners_, corner_active_, n_corners_,
                        pose_lines_,   line_active_,   n_lines_};
  VisibleEdgeSet& visible = scratch.visible;
  MatchConfig match = config_.match;
  FitResult fit;
  constexpr int kRounds = sizeof(config_.round_gates_px) / sizeof(config_.round_gates_px[0]);
  for (int round = 0; round < kRounds; ++round) {
    const float gate = config_.round_gates_px[round];
    // Hidden lines at the start and before the last round (the pose moves little in between;
    // their pieces are matched at the current pose either way).
    if (round == 0 || round == kRounds - 1) {
      const PosedModel posed{&model, c.cam_T_model};
      if (!ComputeVisibleEdges(own, posed, occluders_, n_occluders_, config_.hidden_line_step_px,
                               config_.verify.min_depth_mm, &visible)
               .ok()) {
        ++stats->rejected_matches;
        return false;
      }
    }
    match.corner_gate_px = gate;
    match.line_gate_px = gate;
    MatchFeatures(cam, model, c.cam_T_model, visible, scene, match, &c.matches);
    // Early out: a start pose that finds few of its features within the first (widest) gate
    // rarely ends above the final match fraction.
    const int matched = c.matches.n_points + c.matches.n_lines;
    const int expected = c.matches.corners_expected + c.matches.pieces_expected;
    if (matched < 3 ||
        static_cast<float>(matched) < config_.early_match_fraction * static_cast<float>(expected)) {
      ++stats->rejected_matches;
      return false;
    }
    if (has_table_) {
      fit = FitRestingPose(cam, c.matches, plane_, stable_[basis.model], config_.fit, &scratch.fit,
                           &c.rest);
      c.cam_T_model = RestingTransform(plane_, stable_[basis.model], c.rest);
    } else {
      fit = FitPose(cam, c.matches, config_.fit, &scratch.fit, &c.cam_T_model);
    }
  }
  // Final matches at the refined pose, for the counts and the features the object takes.
  const PosedModel posed{&model, c.cam_T_model};
  // Solids do not interpenetrate: a pose whose centre lies inside an object found before, or
  // that holds such an object's centre, claims that object's place; it may take it from one
  // such object if it explains more of the image (below), never from two.
  c.displaces = -1;
  for (size_t i = 0; i < accepted.size() && config_.exclude_interpenetrating; ++i) {
    const PosedModel other{&table_.model(accepted[i].model),
                           camera_.cam_T_left * accepted[i].cam_T_model};
    if (!Interpenetrate(posed, other)) continue;
    if (c.displaces >= 0 || !config_.displace_weaker || i < n_known_) {
      ++stats->rejected_overlap;
      return false;
    }
    c.displaces = static_cast<int>(i);
  }
  // The object it would displace leaves the occluders: it would not be there to hide anything,
  // neither for the final matches nor for the verification.
  const PosedModel* occluders = occluders_;
  size_t n_occluders = n_occluders_;
  PosedModel others[kMaxOccluders];
  if (c.displaces >= 0 && static_cast<size_t>(c.displaces) < n_occluders_) {
    n_occluders = 0;
    for (size_t o = 0; o < n_occluders_; ++o) {
      if (o != static_cast<size_t>(c.displaces)) others[n_occluders++] = occluders_[o];
    }
    occluders = others;
    if (!ComputeVisibleEdges(own, posed, occluders, n_occluders, config_.hidden_line_step_px,
                             config_.verify.min_depth_mm, &visible)
             .ok()) {
      ++stats->rejected_matches;
      return false;
    }
  }
  MatchFeatures(cam, model, c.cam_T_model, visible, scene, match, &c.matches);
  if (c.matches.n_points + c.matches.n_lines < config_.min_matched_features) {
    ++stats->rejected_matches;
    return false;
  }
  c.fit_rms_px = fit.rms_px;
  // Share of the visible corners and edge pieces that found an image feature.
  const int possible = c.matches.corners_expected + c.matches.pieces_expected;
  c.match_fraction = possible > 0 ? float(c.matches.n_points + c.matches.n_lines) / possible : 0;
  if (!(c.match_fraction >= config_.min_match_fraction)) {
    ++stats->rejected_matches;
    return false;
  }

  // Verification against the edge map, hidden lines and the objects found so far removed.
  ++stats->verifications;
  if (!ComputeVisibleEdges(own, posed, occluders, n_occluders, config_.verify.sample_step_px,
                           config_.verify.min_depth_mm, &visible)
           .ok()) {
    ++stats->rejected_verify;
    return false;
  }
  const ConstEdgeMapView edges{features_->edges.edge, features_->edges.orientation};
  const Result<ImageScore> score = ScoreVisibleEdges(own, visible, edges, config_.verify);
  if (!score.ok() || score->samples < config_.verify.min_samples ||
      static_cast<float>(score->confirmed) <
          config_.verify.min_fraction * static_cast<float>(score->samples)) {
    ++stats->rejected_verify;
    return false;
  }
  c.score = static_cast<float>(score->confirmed) / static_cast<float>(score->samples);
  // Edge samples explained, less a share of those the model predicts but the image lacks: a
  // model fitted inside a larger object explains fewer, a larger model around a smaller one
  // predicts edges that are not there.
  c.evidence = static_cast<float>(score->confirmed) -
               config_.missing_edge_penalty * static_cast<float>(score->samples - score->confirmed);
  if (c.displaces >= 0 &&
      !(c.evidence > accepted[static_cast<size_t>(c.displaces)].verify_evidence)) {
    ++stats->rejected_overlap;
    return false;
  }
  return true;
}

void MonoRecognizer::Remove(size_t index, Vector<RecognizedObject>& objects) {
  ahead_.Clear();  // its features vote again
  for (int i = 0; i < n_claimed_points_[index]; ++i) {
    const int corner = claimed_points_[index][i];
    corner_active_[corner] = CornerMayBase(corner) ? 1 : 0;
  }
  for (int i = 0; i < n_claimed_lines_[index]; ++i) line_active_[claimed_lines_[index][i]] = 1;
  for (size_t o = index; o + 1 < objects.size(); ++o) {
    objects[o] = objects[o + 1];
    object_circle_[o] = object_circle_[o + 1];
    n_claimed_points_[o] = n_claimed_points_[o + 1];
    n_claimed_lines_[o] = n_claimed_lines_[o + 1];
    std::copy_n(claimed_points_[o + 1], n_claimed_points_[o], claimed_points_[o]);
    std::copy_n(claimed_lines_[o + 1], n_claimed_lines_[o], claimed_lines_[o]);
  }
  objects.pop_back();
  // A base tried after the removed object was found saw one object fewer of the list that
  // remains: its "objects found later" start one place earlier.
  for (uint32_t q = 0; q < n_candidates_; ++q) {
    if (tried_at_[q] > index) --tried_at_[q];
  }
  // Occluders and instance numbers follow the objects that remain.
  n_occluders_ = 0;
  for (size_t o = 0; o < objects.size(); ++o) {
    objects[o].instance = 0;
    for (size_t q = 0; q < o; ++q) objects[o].instance += objects[q].model == objects[o].model;
    if (n_occluders_ < kMaxOccluders) {
      occluders_[n_occluders_++] = {&table_.model(objects[o].model),
                                    camera_.cam_T_left * objects[o].cam_T_model};
    }
  }
}

void MonoRecognizer::Accept(const Candidate& c, Vector<RecognizedObject>& objects) {
  ahead_.Clear();  // its features no longer vote
  if (c.displaces >= 0) Remove(static_cast<size_t>(c.displaces), objects);
  RecognizedObject o;
  o.model = c.model;
  for (const RecognizedObject& prev : objects) o.instance += prev.model == c.model;
  o.cam_T_model = left_T_cam_ * c.cam_T_model;
  o.vote = c.vote;
  // Reprojection RMS in pixels -> millimetres at the object's distance.
  o.fit_rms_mm = c.fit_rms_px * c.cam_T_model.t_mm.norm() / ideal_focal_px_;
  o.matched_points = static_cast<uint16_t>(c.matches.n_points);
  o.matched_lines = static_cast<uint16_t>(c.matches.n_lines);
  o.verify_score[0] = c.score;
  o.verify_score[1] = c.match_fraction;
  o.verify_evidence = c.evidence;
  (void)objects.push_back(o);  // capacity checked by the caller
  const size_t index = objects.size() - 1;
  n_claimed_points_[index] = static_cast<uint8_t>(c.matches.n_points);
  n_claimed_lines_[index] = static_cast<uint8_t>(c.matches.n_lines);
  for (int i = 0; i < c.matches.n_points; ++i) {
    corner_active_[c.matches.points[i].scene] = 0;
    claimed_points_[index][i] = c.matches.points[i].scene;
  }
  for (int i = 0; i < c.matches.n_lines; ++i) {
    line_active_[c.matches.lines[i].scene] = 0;
    claimed_lines_[index][i] = c.matches.lines[i].scene;
  }
  if (n_occluders_ < kMaxOccluders) {
    occluders_[n_occluders_++] = {&table_.model(c.model), c.cam_T_model};
  }
  // The object's image circle (ideal pixels): bases inside it that failed before may succeed
  // now that its occlusion is known.
  object_circle_[objects.size() - 1] = ImageCircle(table_.model(c.model), c.cam_T_model);
}

Eigen::Vector3f MonoRecognizer::ImageCircle(const Model& model,
                                            const RigidTransform& cam_T_model) const {
  const Eigen::Vector3f centre = cam_T_model * ModelCentroid(model);
  const float radius_px = 1.5f * max_model_radius_mm_ * ideal_focal_px_ / centre.z();
  return {ideal_focal_px_ * centre.x() / centre.z(), ideal_focal_px_ * centre.y() / centre.z(),
          radius_px};
}

Frame2d MonoRecognizer::BasisFrame(const SceneBasis2d& sb) const {
  if (table_.basis_kind() == AspectBasisKind::kAffine) {
    return AffineFrame(ideal_points_[sb.corners[0]].xy, ideal_points_[sb.corners[1]].xy,
                       ideal_points_[sb.corners[2]].xy);
  }
  return SimilarityFrame(ideal_points_[sb.corners[0]].xy, ideal_points_[sb.corners[1]].xy);
}

bool MonoRecognizer::BasisActive(const SceneBasis2d& sb) const {
  const int nc = BasisCornerCount(table_.basis_kind());
  for (int q = 0; q < nc; ++q) {
    if (!corner_active_[sb.corners[q]]) return false;
  }
  return true;
}

namespace {

// The counts one slot's evaluations add.
void AddEvaluationCounts(const MonoStats& from, MonoStats* to) {
  to->rejected_tilt += from.rejected_tilt;
  to->rejected_depth += from.rejected_depth;
  to->rejected_matches += from.rejected_matches;
  to->rejected_overlap += from.rejected_overlap;
  to->verifications += from.verifications;
  to->rejected_verify += from.rejected_verify;
}

}  // namespace

int MonoRecognizer::VoteBasis(AspectVoter& voter, uint32_t k, AspectHypothesis* out) const {
  const SceneBasis2d& sb = candidates_[k];
  VoteRequest request;
  request.frame = BasisFrame(sb);
  const int nc = BasisCornerCount(table_.basis_kind());
  for (int q = 0; q < nc; ++q) request.exclude[q] = sb.corners[q];
  request.n_exclude = nc;
  request.threshold = config_.vote_threshold;
  KeyRange(request.frame, &request);
  const VoteScene scene{ideal_points_, corner_active_, n_corners_,
                        ideal_lines_,  line_active_,   n_lines_};
  return voter.Vote(scene, request, out, config_.hypotheses_per_basis);
}

bool MonoRecognizer::PassTries(uint32_t k, size_t n_objects) const {
  if (!BasisActive(candidates_[k])) return false;
  return pass_ == 0 ? tried_[k] == 0 : tried_[k] == 1 && NearLaterObject(k, n_objects);
}

int MonoRecognizer::VoteInTurn(uint32_t k, size_t n_objects, uint32_t most, AspectHypothesis* out) {
  if (const BasisVotes* voted = ahead_.Find(k)) {
    std::copy_n(voted->hyps, voted->n, out);
    return voted->n;
  }
  if (!votes_in_parallel()) return VoteBasis(voter_, k, out);
  // This basis and the next ones the pass tries, voted on the scene as it is now; the search
  // only takes those votes while the scene stays so (Accept and Remove throw them away). No
  // more than the budget lets the search try.
  const uint32_t gathered = ahead_.Gather(
      k, n_candidates_, most, [this, n_objects](uint32_t j) { return PassTries(j, n_objects); });
  if (gathered == 1) return VoteBasis(voter_, k, out);
  // Two calls, each with a voter of its own: the caller's, and the one in lent counters.
  const BasisVotes& first = ahead_.ComputeAll(
      parallel_, 2,
      [](void* self, int thread, AheadVotes::Entry& e) {
        auto& m = *static_cast<MonoRecognizer*>(self);
        AspectVoter& voter = thread == 0 ? m.voter_ : m.lent_voter_;
        e.result.n = m.VoteBasis(voter, e.index, e.result.hyps);
      },
      this);
  std::copy_n(first.hyps, first.n, out);
  return first.n;
}

bool MonoRecognizer::TryBasis(uint32_t k, const Vector<RecognizedObject>& objects, MonoStats* stats,
                              Candidate* best) {
  tried_[k] = 2;
  ++stats->scene_bases_tried;
  const Frame2d frame = BasisFrame(candidates_[k]);
  AspectHypothesis hyps[kMaxMonoHypotheses];
  // This basis counts as tried already: the budget allows `most` bases from it on.
  const uint32_t most = max_scene_bases_ - std::min(max_scene_bases_, stats->scene_bases_tried) + 1;
  const int n = VoteInTurn(k, objects.size(), most, hyps);
  stats->hypotheses += static_cast<uint32_t>(n);
  for (int i = 0; i < n; ++i) stats->votes_digest = DigestVote(stats->votes_digest, k, hyps[i]);
  // The hypotheses are evaluated in slots (hypothesis i in slot i % slots, each slot's best the
  // first of most evidence in its order), then the slots' bests compared: the most evidence,
  // the lower index on a tie, as the serial loop keeps the first of most evidence.
  const int slots = std::max(1, std::min(slots_used_, n));
  job_ = {hyps, n, slots, &frame, &objects, best};
  if (slots > 1) {
    parallel_(slots, &MonoRecognizer::EvaluateSlot, this);
  } else {
    EvaluateSlot(this, 0);
  }
  const auto evidence = [&](int s) { return s == 0 ? best->evidence : slots_[s].best.evidence; };
  int winner = -1;
  for (int s = 0; s < slots; ++s) {
    AddEvaluationCounts(slots_[s].stats, stats);
    if (slots_[s].best_index < 0) continue;
    if (winner < 0 || evidence(s) > evidence(winner) ||
        (evidence(s) == evidence(winner) && slots_[s].best_index < slots_[winner].best_index)) {
      winner = s;
    }
  }
  if (winner > 0) *best = slots_[winner].best;
  if (winner < 0) tried_[k] = 1;  // failed: may be retried near objects found later
  return winner >= 0;
}

void MonoRecognizer::EvaluateSlot(void* self, int s) {
  auto& m = *static_cast<MonoRecognizer*>(self);
  const EvaluationJob& job = m.job_;
  SlotScratch& slot = m.slots_[s];
  slot.stats = MonoStats{};
  slot.best_index = -1;
  // Slot 0 keeps its best in the caller's candidate.
  Candidate* best = s == 0 ? job.best : &slot.best;
  for (int i = s; i < job.n; i += job.slots) {
    if (!m.Evaluate(job.hyps[i], *job.frame, *job.objects, slot, &slot.stats, &slot.candidate)) {
      continue;
    }
    if (slot.best_index < 0 || slot.candidate.evidence > best->evidence) {
      *best = slot.candidate;
      slot.best_index = i;
    }
  }
}

bool MonoRecognizer::NearLaterObject(uint32_t k, size_t n_objects) const {
  const Frame2d frame = BasisFrame(candidates_[k]);
  for (size_t o = tried_at_[k]; o < n_objects; ++o) {
    const float reach = object_circle_[o].z();
    if ((frame.origin - object_circle_[o].head<2>()).squaredNorm() <= reach * reach) return true;
  }
  return false;
}

int MonoRecognizer::SharedFeatures(const Candidate& a, const Candidate& b) {
  int shared = 0;
  for (int i = 0; i < b.matches.n_points; ++i) {
    for (int j = 0; j < a.matches.n_points; ++j) {
      if (a.matches.points[j].scene == b.matches.points[i].scene) {
        ++shared;
        break;
      }
    }
  }
  for (int i = 0; i < b.matches.n_lines; ++i) {
    for (int j = 0; j < a.matches.n_lines; ++j) {
      if (a.matches.lines[j].scene == b.matches.lines[i].scene) {
        ++shared;
        break;
      }
    }
  }
  return shared;
}

// The verified candidate best_ (from scene basis k) competes with what the untried scene bases
// on its image corners find: a wrong model fitted to part of an object takes some of the
// object's corners and lines, and the right model, found from another pair of its corners,
// claims the same features and explains more of the image. Candidates that claim mostly the
// same image features are one object: the one with more evidence wins. A base that finds a
// different object is left untried, for its turn in the search.
void MonoRecognizer::ChooseAmongCompetitors(uint32_t k, const Vector<RecognizedObject>& objects,
                                            MonoStats* stats) {
  uint8_t on_object[kMaxCorners2d / 8] = {};
  for (int i = 0; i < best_.matches.n_points; ++i) {
    const int c = best_.matches.points[i].scene;
    on_object[c / 8] = static_cast<uint8_t>(on_object[c / 8] | (1u << (c % 8)));
  }
  const int nc = BasisCornerCount(table_.basis_kind());
  int extra = 0;
  for (uint32_t q = k + 1; q < n_candidates_ && extra < config_.competing_bases; ++q) {
    if (tried_[q] || !BasisActive(candidates_[q])) continue;
    bool touches = false;
    for (int c = 0; c < nc; ++c) {
      const int corner = candidates_[q].corners[c];
      touches = touches || (on_object[corner / 8] & (1u << (corner % 8))) != 0;
    }
    if (!touches) continue;
    ++extra;
    tried_at_[q] = static_cast<uint8_t>(objects.size());
    if (!TryBasis(q, objects, stats, &other_)) continue;
    const int shared = SharedFeatures(best_, other_);
    const int smaller = std::min(best_.matches.n_points + best_.matches.n_lines,
                                 other_.matches.n_points + other_.matches.n_lines);
    const bool same_place =
        static_cast<float>(shared) >= config_.competing_overlap * static_cast<float>(smaller) ||
        (config_.exclude_interpenetrating &&
         Interpenetrate({&table_.model(best_.model), best_.cam_T_model},
                        {&table_.model(other_.model), other_.cam_T_model}));
    if (!same_place) {
      tried_[q] = 0;  // another object: its turn comes
      continue;
    }
    if (other_.evidence > best_.evidence) best_ = other_;
  }
}

Status MonoRecognizer::Recognize(const ImageFeatures& features, const Budget& budget,
                                 Vector<RecognizedObject>& objects, MonoStats* stats_out) {
  objects.clear();
  MonoStats local;
  MonoStats& stats = stats_out != nullptr ? *stats_out : local;
  stats = MonoStats{};
  if (!initialised_) {
    return Status::Error(StatusCode::kFailedPrecondition, "mono: Init() has not succeeded");
  }
  // The per-object state (circles, claimed features) holds kMaxObjects objects.
  if (objects.capacity() > kMaxObjects) {
    return Status::Error(StatusCode::kInvalidArgument,
                         "mono: the result holds %zu objects, at most %zu are tracked",
                         objects.capacity(), size_t{kMaxObjects});
  }
  SH_RETURN_IF_ERROR(PrepareScene(features, nullptr));
  Search(budget, objects, 0, &stats);
  return Status::Ok();
}

Status MonoRecognizer::RecognizeRest(const ImageFeatures& features, const FeatureMask& ignore,
                                     const Budget& budget, Vector<RecognizedObject>& objects,
                                     size_t n_known, MonoStats* stats_out) {
  MonoStats local;
  MonoStats& stats = stats_out != nullptr ? *stats_out : local;
  stats = MonoStats{};
  if (!initialised_) {
    return Status::Error(StatusCode::kFailedPrecondition, "mono: Init() has not succeeded");
  }
  if (objects.capacity() > kMaxObjects || n_known > objects.size()) {
    return Status::Error(StatusCode::kInvalidArgument,
                         "mono: %zu known objects of %zu, a result of %zu (at most %zu tracked)",
                         n_known, objects.size(), objects.capacity(), size_t{kMaxObjects});
  }
  for (size_t i = 0; i < n_known; ++i) {
    if (objects[i].model >= table_.model_count()) {
      return Status::Error(StatusCode::kInvalidArgument, "mono: known object %zu has model %u", i,
                           unsigned{objects[i].model});
    }
  }
  (void)objects.resize(n_known);
  SH_RETURN_IF_ERROR(PrepareScene(features, &ignore));
  Search(budget, objects, n_known, &stats);
  return Status::Ok();
}

void MonoRecognizer::Search(const Budget& budget, Vector<RecognizedObject>& objects, size_t n_known,
                            MonoStats* stats_ptr) {
  MonoStats& stats = *stats_ptr;
  GenerateBases();
  stats.scene_bases_available = n_candidates_;
  stats.aspects_enabled = aspects_enabled_;
  // The known objects: occluders, with no image features of their own to give back.
  n_known_ = n_known;
  n_occluders_ = 0;
  for (size_t o = 0; o < n_known; ++o) {
    const RigidTransform cam_T_model = camera_.cam_T_left * objects[o].cam_T_model;
    if (n_occluders_ < kMaxOccluders) {
      occluders_[n_occluders_++] = {&table_.model(objects[o].model), cam_T_model};
    }
    n_claimed_points_[o] = n_claimed_lines_[o] = 0;
    object_circle_[o] = ImageCircle(table_.model(objects[o].model), cam_T_model);
  }
  for (uint32_t k = 0; k < n_candidates_; ++k) tried_[k] = 0;
  ahead_.Clear();
  max_scene_bases_ = budget.max_scene_bases;
  // Two passes: every scene basis in order, then the bases that failed before an object was
  // found near them (that object hides parts of theirs, which verification now knows).
  for (int pass = 0; pass < 2; ++pass) {
    pass_ = pass;
    ahead_.Clear();
    uint32_t fruitless = 0;
    for (uint32_t k = 0; k < n_candidates_; ++k) {
      if (stats.scene_bases_tried >= budget.max_scene_bases || DeadlinePassed(budget)) {
        stats.budget_exhausted = true;
        return;
      }
      if (objects.full()) {
        stats.objects_full = true;
        return;
      }
      if (!PassTries(k, objects.size())) continue;
      tried_at_[k] = static_cast<uint8_t>(objects.size());
      if (!TryBasis(k, objects, stats_ptr, &best_)) {
        if (pass == 1) tried_[k] = 2;  // one retry only
        if (++fruitless >= config_.max_fruitless_bases) break;
        continue;
      }
      fruitless = 0;
      ChooseAmongCompetitors(k, objects, stats_ptr);
      Accept(best_, objects);
      ++stats.accepted;
    }
  }
}

Status MonoRecognizer::Diagnose(const ImageFeatures& features, int model_index,
                                const RigidTransform& left_T_model, MonoDiagnosis* out) {
  *out = MonoDiagnosis{};
  if (!initialised_) {
    return Status::Error(StatusCode::kFailedPrecondition, "mono: Init() has not succeeded");
  }
  if (model_index < 0 || model_index >= static_cast<int>(table_.model_count())) {
    return Status::Error(StatusCode::kInvalidArgument, "mono: no model %d", model_index);
  }
  SH_RETURN_IF_ERROR(PrepareScene(features, nullptr));
  GenerateBases();
  n_occluders_ = 0;
  n_known_ = 0;
  const Model& model = table_.model(static_cast<uint32_t>(model_index));
  const CameraIntrinsics& cam = camera_.intrinsics;
  const RigidTransform cam_T_model = camera_.cam_T_left * left_T_model;
  const ViewCamera own{cam, RigidTransform::Identity()};
  VisibleEdgeSet visible;
  SH_RETURN_IF_ERROR(ComputeVisibleEdges(own, {&model, cam_T_model}, nullptr, 0,
                                         config_.hidden_line_step_px, config_.verify.min_depth_mm,
                                         &visible));
  Eigen::Vector2f projected[kMaxModelCorners];
  const double max_r2 = MaxImageRadius2(cam);
  for (int i = 0; i < model.n_corners; ++i) {
    if (!ProjectInView(cam, max_r2, cam_T_model * model.corner(i), &projected[i])) {
      projected[i] = Eigen::Vector2f(1e9f, 1e9f);
    }
  }
  const CornerMask corners =
      VisibleCorners2d(model, visible, projected, config_.match.min_corner_angle_deg);
  // Image corners at the model's corners.
  uint8_t on_object[kMaxCorners2d] = {};
  for (int i = 0; i < model.n_corners; ++i) {
    if (!corners.test(static_cast<size_t>(i))) continue;
    ++out->corners_visible;
    bool detected = false;
    for (int k = 0; k < n_corners_; ++k) {
      if ((pose_corners_[k].px - projected[i]).norm() <= 3.0f) {
        on_object[k] = 1;
        detected = true;
      }
    }
    out->corners_detected += detected;
  }
  PoseMatches matches;
  MatchConfig match = config_.match;
  match.corner_gate_px = match.line_gate_px = 3.0f;
  const PoseScene scene{pose_corners_, nullptr, n_corners_, pose_lines_, nullptr, n_lines_};
  MatchFeatures(cam, model, cam_T_model, visible, scene, match, &matches);
  out->pieces_detected = matches.n_lines;
  for (int k = 0; k < visible.n_edges; ++k) {
    const VisibleEdge& ve = visible.edges[k];
    for (int r = 0; r < ve.n_runs; ++r) {
      Eigen::Vector2f a, b;
      const float s0 = float(ve.runs[r].first) / ve.n_samples,
                  s1 = float(ve.runs[r].end) / ve.n_samples;
      if (ProjectInView(cam, max_r2, PointAtImageFraction(ve, s0), &a) &&
          ProjectInView(cam, max_r2, PointAtImageFraction(ve, s1), &b) &&
          (b - a).norm() >= match.min_piece_px) {
        ++out->pieces_visible;
      }
    }
  }
  VisibleEdgeSet samples;
  SH_RETURN_IF_ERROR(ComputeVisibleEdges(own, {&model, cam_T_model}, nullptr, 0,
                                         config_.verify.sample_step_px, config_.verify.min_depth_mm,
                                         &samples));
  const ConstEdgeMapView edges{features.edges.edge, features.edges.orientation};
  const Result<ImageScore> score = ScoreVisibleEdges(own, samples, edges, config_.verify);
  if (score.ok() && score->samples > 0) {
    out->verify_samples = score->samples;
    out->verify_fraction = float(score->confirmed) / float(score->samples);
  }
  // Every candidate basis on two of the object's corners, evaluated alone.
  const bool affine = table_.basis_kind() == AspectBasisKind::kAffine;
  const int nc = affine ? 3 : 2;
  Vector<RecognizedObject, 1> none;
  MonoStats& stats = out->stats;
  AspectHypothesis hyps[kMaxMonoHypotheses];
  Candidate candidate;
  for (uint32_t k = 0; k < n_candidates_; ++k) {
    const SceneBasis2d& sb = candidates_[k];
    bool on = true;
    for (int q = 0; q < nc; ++q) on = on && on_object[sb.corners[q]];
    if (!on) continue;
    ++out->object_bases;
    const Frame2d frame =
        affine ? AffineFrame(ideal_points_[sb.corners[0]].xy, ideal_points_[sb.corners[1]].xy,
                             ideal_points_[sb.corners[2]].xy)
               : SimilarityFrame(ideal_points_[sb.corners[0]].xy, ideal_points_[sb.corners[1]].xy);
    VoteRequest request;
    request.frame = frame;
    for (int q = 0; q < nc; ++q) request.exclude[q] = sb.corners[q];
    request.n_exclude = nc;
    request.threshold = config_.vote_threshold;
    KeyRange(frame, &request);
    const VoteScene vs{ideal_points_, corner_active_, n_corners_,
                       ideal_lines_,  line_active_,   n_lines_};
    const int n = voter_.Vote(vs, request, hyps, config_.hypotheses_per_basis);
    bool has_model = false, found = false;
    for (int i = 0; i < n; ++i) {
      if (table_.basis(hyps[i].basis).model != model_index) continue;
      has_model = true;
      ++stats.hypotheses;
      if (!Evaluate(hyps[i], frame, none, slots_[0], &stats, &candidate)) continue;
      const float dt = (candidate.cam_T_model.t_mm - cam_T_model.t_mm).norm();
      found = found || dt < 5.0f;
    }
    out->bases_with_model += has_model;
    out->bases_found += found;
    if (found && out->best_rank < 0) out->best_rank = static_cast<int>(k);
  }
  return Status::Ok();
}

}  // namespace sh
