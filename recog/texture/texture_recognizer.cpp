#include "recog/texture/texture_recognizer.hpp"

#include <algorithm>
#include <cmath>
#include <tuple>

#include "recog/texture/absolute_orientation.hpp"

namespace sh::texture {
namespace {

Eigen::Vector3f Vec3(const float* v) { return {v[0], v[1], v[2]}; }

// Face frame of a printed face: model point = origin + a axis_a + b axis_b.
struct FaceFrame {
  Eigen::Vector3f o, a, b, n;
  explicit FaceFrame(const TexturedFace& f)
      : o(Vec3(f.origin_mm)), a(Vec3(f.axis_a)), b(Vec3(f.axis_b)), n(a.cross(b)) {}
  Eigen::Vector3f Point(float aa, float bb) const { return o + aa * a + bb * b; }
  Eigen::Vector2f Coordinates(const Eigen::Vector3f& x) const {
    return {(x - o).dot(a), (x - o).dot(b)};
  }
  // face_T_model: model point -> (a, b, height above the face).
  RigidTransform FaceFromModel() const {
    RigidTransform t;
    t.R.row(0) = a.transpose();
    t.R.row(1) = b.transpose();
    t.R.row(2) = n.transpose();
    t.t_mm = -(t.R * o);
    return t;
  }
};

// Distorted pixel of an ideal (undistorted) pixel.
Eigen::Vector2d DistortIdeal(const CameraIntrinsics& cam, const Eigen::Vector2d& ideal) {
  const Eigen::Vector2d d =
      Distort(cam, {(ideal.x() - cam.cx) / cam.fx, (ideal.y() - cam.cy) / cam.fy});
  return {cam.fx * d.x() + cam.cx, cam.fy * d.y() + cam.cy};
}

}  // namespace

Status TextureRecognizer::Init(const StereoCalibration& calib, const FeatureDbView& db,
                               const TextureRecognizerConfig& config, ClockFn now_ns,
                               const ParallelFor& parallel) {
  initialised_ = false;
  if (db.empty()) {
    return Status::Error(StatusCode::kFailedPrecondition,
                         "texture recogniser: no feature database");
  }
  if (calib.left.width <= 0 || calib.left.height <= 0 || calib.left.width > kMaxImageWidth ||
      calib.left.height > kMaxImageHeight || calib.right.width > kMaxImageWidth ||
      calib.right.height > kMaxImageHeight) {
    return Status::Error(StatusCode::kOutOfRange,
                         "texture recogniser: image size %dx%d outside 1..%dx%d", calib.left.width,
                         calib.left.height, kMaxImageWidth, kMaxImageHeight);
  }
  extraction_ = ExtractionConfig(db.header().extraction);
  extraction_.max_keypoints = std::min(config.max_keypoints, kMaxTextureKeypoints);
  if (const Status valid = extraction_.Validate(); !valid.ok()) {
    return Status::Error(StatusCode::kDataLoss,
                         "texture recogniser: the feature database's extraction settings: %s",
                         valid.message());
  }
  if (config.hough.n_scales < 1 || config.hough.n_scales > kMaxHoughScales ||
      !(config.hough.resolution > 0.0f && config.hough.resolution <= 1.0f)) {
    return Status::Error(StatusCode::kOutOfRange,
                         "texture recogniser: Hough needs 1..%d scales and a resolution in (0, 1]",
                         kMaxHoughScales);
  }
  if (config.matching.max_checks < 1 ||
      !(config.matching.ratio > 0.0f && config.matching.ratio <= 1.0f)) {
    return Status::Error(StatusCode::kOutOfRange,
                         "texture recogniser: matching needs max_checks >= 1 and ratio in (0, 1]");
  }
  if (config.stereo.window_radius_px < 1 || config.stereo.window_radius_px > kMaxZnccRadiusPx ||
      config.stereo.max_points < 3 ||
      config.stereo.max_points > static_cast<int>(kMaxFaceStereoPoints)) {
    return Status::Error(StatusCode::kOutOfRange,
                         "texture recogniser: stereo window radius 1..%d and 3..%zu points",
                         kMaxZnccRadiusPx, kMaxFaceStereoPoints);
  }
  if (config.auto_scales &&
      !(config.min_depth_mm > 0.0f && config.max_depth_mm > config.min_depth_mm)) {
    return Status::Error(
        StatusCode::kOutOfRange, "texture recogniser: depth range %.0f .. %.0f mm is empty",
        static_cast<double>(config.min_depth_mm), static_cast<double>(config.max_depth_mm));
  }
  calib_ = calib;
  db_ = db;
  config_ = config;
  if (config.auto_scales) {
    ScalesForCamera(0.5 * (calib.left.fx + calib.left.fy), db.header().feature_px_per_mm,
                    config.min_depth_mm, config.max_depth_mm, &config_.hough);
  }
  now_ns_ = now_ns;
  parallel_ = parallel;
  initialised_ = true;
  return Status::Ok();
}

float TextureRecognizer::MsSince(int64_t start_ns) const {
  return now_ns_ ? static_cast<float>(now_ns_() - start_ns) * 1e-6f : 0.0f;
}

void TextureRecognizer::MatchBand(int band) {
  const KdTreeView tree = db_.tree();
  const float ratio2 = config_.matching.ratio * config_.matching.ratio;
  const float same2 = config_.matching.same_point_mm * config_.matching.same_point_mm;
  const size_t n_kp = features_.keypoints.size();
  const size_t begin = n_kp * static_cast<size_t>(band) / kParallelBands;
  const size_t end = n_kp * static_cast<size_t>(band + 1) / kParallelBands;
  KdSearcher& searcher = searchers_[band];
  for (size_t i = begin; i < end; ++i) {
    match_of_[i] = UINT32_MAX;
    KdNeighbour nb[kMatchNeighbours];
    const int n = searcher.Search(tree, features_.descriptors[i], kMatchNeighbours,
                                  config_.matching.max_checks, nb);
    if (n == 0) continue;
    const FeatureRecord& f0 = db_.feature(nb[0].index);
    const uint16_t face0 = db_.view(f0.view).face;
    const Eigen::Vector3f x0 = Vec3(f0.model_mm);
    // Distance of the nearest other physical point: another face, or the same face further
    // than same_point_mm (the same point learnt in several views and levels does not count).
    // If all k neighbours are the same point, the k-th distance bounds it from below.
    uint32_t other = n < kMatchNeighbours ? UINT32_MAX : nb[n - 1].dist2;
    for (int j = 1; j < n; ++j) {
      const FeatureRecord& fj = db_.feature(nb[j].index);
      if (db_.view(fj.view).face != face0 || (Vec3(fj.model_mm) - x0).squaredNorm() > same2) {
        other = nb[j].dist2;
        break;
      }
    }
    if (static_cast<float>(nb[0].dist2) < ratio2 * static_cast<float>(other)) {
      match_of_[i] = nb[0].index;
    }
  }
}

void TextureRecognizer::MatchFeatures() {
  // Bands of keypoints over the threads, each with its own searcher; then the matches in
  // keypoint order.
  parallel_(
      kParallelBands,
      [](void* self, int band) { static_cast<TextureRecognizer*>(self)->MatchBand(band); }, this);
  matches_.clear();
  for (size_t i = 0; i < features_.keypoints.size(); ++i) {
    if (match_of_[i] != UINT32_MAX)
      (void)matches_.push_back({static_cast<uint16_t>(i), match_of_[i]});
  }
}

void TextureRecognizer::FindFaces() {
  for (size_t i = 0; i < matches_.size(); ++i) {
    const Match& m = matches_[i];
    const TextureKeypoint& kp = features_.keypoints[m.keypoint];
    const FeatureRecord& f = db_.feature(m.feature);
    HoughInput& in = hough_inputs_[i];
    in.x_px = ideal_px_[m.keypoint].x();
    in.y_px = ideal_px_[m.keypoint].y();
    in.angle_rad = kp.angle_rad;
    in.u_px = f.u_px;
    in.v_px = f.v_px;
    in.db_angle_rad = f.angle_rad;
    in.face = db_.view(f.view).face;
  }
  hough_.Vote(hough_inputs_, matches_.size(), config_.hough);
  hough_.Clusters(config_.hough, clusters_);
  std::fill(keypoint_used_, keypoint_used_ + kMaxTextureKeypoints, false);
  for (const HoughCluster& c : clusters_) {
    if (detections_.full()) break;
    hough_.ClusterMatches(c, cluster_matches_);
    const FaceFrame frame(db_.face(c.face));
    auto collect = [&] {
      cluster_planar_.clear();
      for (uint16_t mi : cluster_matches_) {
        const Match& m = matches_[mi];
        if (keypoint_used_[m.keypoint]) continue;
        const Eigen::Vector2f ab = frame.Coordinates(Vec3(db_.feature(m.feature).model_mm));
        PlanarMatch pm;
        pm.a_mm = ab.x();
        pm.b_mm = ab.y();
        pm.x_px = ideal_px_[m.keypoint].x();
        pm.y_px = ideal_px_[m.keypoint].y();
        pm.keypoint = m.keypoint;
        pm.feature = m.feature;
        (void)cluster_planar_.push_back(pm);
      }
    };
    collect();
    if (cluster_planar_.size() < static_cast<size_t>(config_.planar.min_matches)) continue;
    PlanarFit fit = FitFacePlane(cluster_planar_, config_.planar);
    if (!fit.accepted) {
      // More gross outliers than the mean-based rounds remove (a repeated print element
      // matched at several places): again from the largest consensus of an affine map.
      collect();
      if (KeepAffineConsensus(cluster_planar_, config_.planar) &&
          cluster_planar_.size() >= static_cast<size_t>(config_.planar.min_matches)) {
        fit = FitFacePlane(cluster_planar_, config_.planar);
      }
    }
    if (!fit.accepted) continue;
    const TexturedFace& face = db_.face(c.face);
    (void)LimitPerspective(face.corners_ab_mm, face.n_corners, cluster_planar_,
                           config_.min_depth_mm, &fit);
    // The print seen from the front: a mirrored mapping is no view of the face.
    const Eigen::Matrix3d& H = fit.image_H_face;
    if ((H(0, 0) * H(1, 1) - H(0, 1) * H(1, 0)) * H(2, 2) >= 0.0) continue;  // b up, y down
    if (planar_.size() + cluster_planar_.size() > planar_.capacity()) break;
    FaceDetection d;
    d.face = c.face;
    d.fit = fit;
    d.first_match = static_cast<uint16_t>(planar_.size());
    d.n_matches = static_cast<uint16_t>(cluster_planar_.size());
    for (const PlanarMatch& pm : cluster_planar_) {
      (void)planar_.push_back(pm);
      keypoint_used_[pm.keypoint] = true;
    }
    (void)detections_.push_back(d);
  }
}

void TextureRecognizer::LocateFace(size_t index) {
  FaceDetection& d = detections_[index];
  Vector<Eigen::Vector2f>& contour_points = face_scratch_[index].contour;
  Vector<StereoPoint>& face_stereo = face_scratch_[index].stereo;
  const TexturedFace& face = db_.face(d.face);
  const FaceFrame frame(face);
  const CameraIntrinsics& cam = calib_.left;
  // The face's contour in the (distorted) left image, from the homography.
  Eigen::Vector2f contour[kMaxTexturedFaceCorners];
  for (int k = 0; k < face.n_corners; ++k) {
    const Eigen::Vector2d px =
        ApplyHomography(d.fit.image_H_face, face.corners_ab_mm[k][0], face.corners_ab_mm[k][1]);
    contour[k] = DistortIdeal(cam, px).cast<float>();
  }
  // Provisional plane: its depth at the matches' centroid from the image scale there of the
  // matches' least-squares affine map, its tilt from the homography's pose when that pose agrees
  // with this depth; otherwise facing the camera (the correlation window then follows only the
  // rotation between the cameras). The affine map at the centroid, not the homography at the
  // face's centre: few matches (5 to 10 on a small face far away) fix the homography's
  // perspective terms poorly, and its scale, extrapolated or not, was off by up to 17 %, more
  // than the depth search's interval; the affine map's six parameters are fixed well by them.
  float ca = 0.0f, cb = 0.0f;
  for (uint16_t k = 0; k < d.n_matches; ++k) {
    ca += planar_[d.first_match + k].a_mm;
    cb += planar_[d.first_match + k].b_mm;
  }
  ca /= static_cast<float>(std::max<uint16_t>(1, d.n_matches));
  cb /= static_cast<float>(std::max<uint16_t>(1, d.n_matches));
  Eigen::Matrix<double, 2, 3> affine;
  if (!FitAffine(planar_.data() + d.first_match, d.n_matches, &affine)) return;
  Eigen::Matrix3d image_A_face = Eigen::Matrix3d::Identity();
  image_A_face.topRows<2>() = affine;
  const double scale = MaxImageScale(image_A_face, ca, cb);
  if (!(scale > 0)) return;
  const Eigen::Vector2d centre_px = ApplyHomography(d.fit.image_H_face, ca, cb);
  const Eigen::Vector3d centre_ray((centre_px.x() - cam.cx) / cam.fx,
                                   (centre_px.y() - cam.cy) / cam.fy, 1.0);
  const double depth = 0.5 * (cam.fx + cam.fy) / scale;  // along the optical axis
  const Eigen::Vector3d centre = centre_ray * depth;
  Plane3 prior;
  prior.normal = -centre.normalized();
  RigidTransform cam_T_face;
  if (PoseFromHomography(d.fit.image_H_face, cam.fx, cam.fy, cam.cx, cam.cy, &cam_T_face)) {
    const double z_h = (cam_T_face * Eigen::Vector3f(ca, cb, 0.0f)).z();
    if (std::fabs(z_h / depth - 1.0) < config_.stereo.depth_search_fraction) {
      prior.normal = cam_T_face.R.col(2).cast<double>();
    }
  }
  prior.d_mm = prior.normal.dot(centre);
  SelectContourPoints(extractor_.min_eigenvalue(), contour, face.n_corners, config_.stereo,
                      contour_points);
  auto correlate = [&](const Plane3& along) {
    face_stereo.clear();
    for (const Eigen::Vector2f& p : contour_points) {
      StereoPoint sp;
      if (stereo_matcher_.Match(p, along, config_.stereo, &sp)) (void)face_stereo.push_back(sp);
    }
  };
  correlate(prior);
  // A tilt from the homography that warps the window wrongly: retry facing the camera.
  if (face_stereo.size() < static_cast<size_t>(config_.stereo.min_plane_points) &&
      prior.normal.dot(centre.normalized()) > -0.999) {
    prior.normal = -centre.normalized();
    prior.d_mm = prior.normal.dot(centre);
    correlate(prior);
  }
  Plane3 plane;
  bool fitted = FitPlaneRansac(face_stereo, config_.stereo, &plane, &d.plane);
  // The window shaped by a poor provisional tilt (a small face seen obliquely, its homography's
  // tilt not trusted, facing the camera assumed): few points correlate, and the plane through
  // them is rough. Once more with the measured plane as the prior (from as few as
  // min_prior_points when no plane had enough), kept when it has at least as many inliers.
  Plane3 rough = plane;
  PlaneFitStats rough_stats = d.plane;
  PlaneStereoConfig relaxed = config_.stereo;
  relaxed.min_plane_points = config_.stereo.min_prior_points;
  const bool have_rough = fitted || FitPlaneRansac(face_stereo, relaxed, &rough, &rough_stats);
  const double cos_limit = std::cos(config_.stereo.prior_retry_deg * 3.14159265358979 / 180.0);
  if (have_rough && (!fitted || d.plane.inliers * 2 < static_cast<int>(contour_points.size()) ||
                     rough.normal.dot(prior.normal) < cos_limit)) {
    const int first_inliers = fitted ? d.plane.inliers : 0;
    correlate(rough);
    PlaneFitStats second_stats;
    Plane3 second;
    if (FitPlaneRansac(face_stereo, config_.stereo, &second, &second_stats) &&
        second_stats.inliers >= first_inliers) {
      plane = second;
      d.plane = second_stats;
      fitted = true;
    } else if (fitted) {
      correlate(prior);
      fitted = FitPlaneRansac(face_stereo, config_.stereo, &plane, &d.plane);
    }
  }
  if (!fitted) return;
  // Corner rays (from the homography, ideal pixels) cut with the measured plane; Horn against
  // the model's corners.
  Eigen::Vector3d measured[kMaxTexturedFaceCorners], model_corners[kMaxTexturedFaceCorners];
  for (int k = 0; k < face.n_corners; ++k) {
    const Eigen::Vector2d px =
        ApplyHomography(d.fit.image_H_face, face.corners_ab_mm[k][0], face.corners_ab_mm[k][1]);
    const Eigen::Vector3d ray =
        Eigen::Vector3d((px.x() - cam.cx) / cam.fx, (px.y() - cam.cy) / cam.fy, 1.0).normalized();
    if (!IntersectRayPlane(ray, plane, &measured[k])) return;
    model_corners[k] =
        frame.Point(face.corners_ab_mm[k][0], face.corners_ab_mm[k][1]).cast<double>();
  }
  if (!AbsoluteOrientation(model_corners, measured, nullptr, face.n_corners, &d.cam_T_model))
    return;
  // The plane's inliers first.
  size_t kept = 0;
  for (size_t i = 0; i < face_stereo.size(); ++i) {
    if (face_stereo[i].inlier) face_stereo[kept++] = face_stereo[i];
  }
  (void)face_stereo.resize(kept);
  d.n_stereo = static_cast<uint16_t>(kept);
  d.posed = true;
}

void TextureRecognizer::AssembleObjects(TextureResult* out) {
  // Group the posed faces into objects: same model, agreeing poses. Detections come strongest
  // first (the Hough order), so each group's first member is its strongest face.
  int group_of[kMaxFaceDetections];
  int n_groups = 0;
  int group_first[kMaxFaceDetections];
  for (size_t i = 0; i < detections_.size(); ++i) {
    group_of[i] = -1;
    const FaceDetection& d = detections_[i];
    if (!d.posed) continue;
    const uint16_t model = db_.face(d.face).model;
    for (int g = 0; g < n_groups && group_of[i] < 0; ++g) {
      const FaceDetection& lead = detections_[static_cast<size_t>(group_first[g])];
      if (db_.face(lead.face).model != model) continue;
      const float dist = (lead.cam_T_model.t_mm - d.cam_T_model.t_mm).norm();
      const float angle = RotationAngleDeg(lead.cam_T_model.R.transpose() * d.cam_T_model.R);
      if (dist < config_.merge_distance_mm && angle < config_.merge_angle_deg) group_of[i] = g;
    }
    if (group_of[i] < 0) {
      group_first[n_groups] = static_cast<int>(i);
      group_of[i] = n_groups++;
    }
  }
  out->stats.hypotheses = static_cast<uint32_t>(n_groups);
  // Strongest groups first: total correspondences.
  int order[kMaxFaceDetections];
  int strength[kMaxFaceDetections] = {};
  for (size_t i = 0; i < detections_.size(); ++i) {
    if (group_of[i] >= 0) strength[group_of[i]] += detections_[i].n_matches;
  }
  for (int g = 0; g < n_groups; ++g) order[g] = g;
  // Ties keep group order (std::stable_sort would take a heap buffer).
  std::sort(order, order + n_groups, [&](int a, int b) {
    return strength[a] > strength[b] || (strength[a] == strength[b] && a < b);
  });

  // Each group's pose, refined; verification follows once all are known.
  candidates_.clear();
  for (int oi = 0; oi < n_groups && !candidates_.full(); ++oi) {
    const int g = order[oi];
    const FaceDetection& lead = detections_[static_cast<size_t>(group_first[g])];
    const uint16_t model = db_.face(lead.face).model;
    size_t nf = 0, ns = 0;
    TextureObject obj;
    obj.model = model;
    obj.cam_T_model = lead.cam_T_model;
    for (size_t i = 0; i < detections_.size(); ++i) {
      if (group_of[i] != g) continue;
      const FaceDetection& d = detections_[i];
      ++obj.faces;
      obj.plane_mean_mm += static_cast<float>(d.plane.mean_abs_mm);
      obj.plane_max_mm = std::max(obj.plane_max_mm, static_cast<float>(d.plane.max_abs_mm));
      for (uint16_t k = 0; k < d.n_matches && nf < kMaxPoseObservations; ++k) {
        const PlanarMatch& pm = planar_[d.first_match + k];
        const TextureKeypoint& kp = features_.keypoints[pm.keypoint];
        PoseFeatureObservation& o = feature_obs_[nf++];
        o.model_mm = Vec3(db_.feature(pm.feature).model_mm).cast<double>();
        o.left_px = Eigen::Vector2d(kp.x_px, kp.y_px);
        o.sigma_px = 0.7 * kp.scale;  // Harris maxima localise to about a level pixel
      }
      const FaceFrame frame(db_.face(d.face));
      for (uint16_t k = 0; k < d.n_stereo && ns < kMaxPoseObservations; ++k) {
        const StereoPoint& sp = face_scratch_[i].stereo[k];
        PoseStereoObservation& o = stereo_obs_[ns++];
        o.left_px = sp.left_px.cast<double>();
        o.right_px = sp.right_px.cast<double>();
        o.plane_normal_model = frame.n.cast<double>();
        o.plane_d_mm = frame.n.dot(frame.o);
      }
    }
    obj.plane_mean_mm /= static_cast<float>(std::max<uint16_t>(1, obj.faces));
    PoseRefineStats rs;
    if (refiner_.Refine(calib_, feature_obs_, nf, stereo_obs_, ns, config_.refine, &obj.cam_T_model,
                        &rs)) {
      obj.feature_matches = static_cast<uint16_t>(rs.features_used);
      obj.stereo_points = static_cast<uint16_t>(rs.stereo_used);
      obj.feature_rms_px = static_cast<float>(rs.feature_rms_px);
      obj.stereo_rms_px = static_cast<float>(rs.stereo_rms_px);
    } else {
      obj.feature_matches = static_cast<uint16_t>(nf);
      obj.stereo_points = static_cast<uint16_t>(ns);
    }
    (void)candidates_.push_back(obj);
  }
  // Verification passes: an object hidden in part by another is verified again once that one
  // is accepted (its samples there no longer count), until a pass accepts nothing new.
  HypothesisOutcome outcome[kMaxFaceDetections];
  for (size_t i = 0; i < candidates_.size(); ++i) outcome[i] = HypothesisOutcome::kPrintRejected;
  bool pending[kMaxFaceDetections];
  std::fill(pending, pending + candidates_.size(), true);
  PlacedModel placed[kMaxTextureObjects];
  for (bool progress = true; progress;) {
    progress = false;
    for (size_t i = 0; i < candidates_.size(); ++i) {
      if (!pending[i]) continue;
      TextureObject& obj = candidates_[i];
      bool duplicate = false;
      for (const TextureObject& a : out->objects) {
        duplicate |=
            (a.cam_T_model.t_mm - obj.cam_T_model.t_mm).norm() < config_.duplicate_distance_mm;
      }
      if (duplicate) {
        pending[i] = false;
        outcome[i] = HypothesisOutcome::kDuplicate;
        continue;
      }
      if (out->objects.full()) {
        pending[i] = false;
        outcome[i] = HypothesisOutcome::kObjectsFull;
        continue;
      }
      obj.print =
          verifier_.Score(obj.model, obj.cam_T_model, placed, out->objects.size(), config_.verify);
      if (!PrintVerifier::Accept(obj.print, config_.verify)) continue;
      pending[i] = false;
      outcome[i] = HypothesisOutcome::kAccepted;
      placed[out->objects.size()] = {&db_.model(obj.model), obj.cam_T_model};
      (void)out->objects.push_back(obj);
      progress = true;
    }
  }
  for (size_t i = 0; i < candidates_.size(); ++i) {
    const TextureObject& obj = candidates_[i];
    TextureHypothesisInfo info;
    info.model = obj.model;
    info.faces = obj.faces;
    info.cam_T_model = obj.cam_T_model;
    info.print = obj.print;
    info.outcome = outcome[i];
    out->stats.rejected += outcome[i] == HypothesisOutcome::kAccepted ? 0 : 1;
    (void)out->hypotheses.push_back(info);
  }
}

Status TextureRecognizer::Process(ConstGrayView left, ConstGrayView right, TextureResult* out) {
  out->objects.clear();
  out->faces.clear();
  out->hypotheses.clear();
  out->stats = {};
  out->time = {};
  if (!initialised_) {
    return Status::Error(StatusCode::kFailedPrecondition, "texture recogniser: not initialised");
  }
  for (const auto& [img, cam, name] :
       {std::tuple{left, &calib_.left, "left"}, std::tuple{right, &calib_.right, "right"}}) {
    SH_RETURN_IF_ERROR(ValidateGrayImage(img, name));
    if (img.width != cam->width || img.height != cam->height) {
      return Status::Error(StatusCode::kInvalidArgument,
                           "texture recogniser: %s image %dx%d, calibration says %dx%d", name,
                           img.width, img.height, cam->width, cam->height);
    }
  }
  left_ = left;
  right_ = right;
  const int64_t t0 = now_ns_ ? now_ns_() : 0;
  int64_t t = t0;
  auto lap = [&](float* ms) {
    if (!now_ns_) return;
    const int64_t now = now_ns_();
    *ms = static_cast<float>(now - t) * 1e-6f;
    t = now;
  };
  SH_RETURN_IF_ERROR(extractor_.Extract(left, extraction_, &features_, parallel_));
  for (size_t i = 0; i < features_.keypoints.size(); ++i) {
    const TextureKeypoint& kp = features_.keypoints[i];
    const Eigen::Vector2d n = UndistortPixel(calib_.left, {kp.x_px, kp.y_px});
    ideal_px_[i] = Eigen::Vector2f(static_cast<float>(calib_.left.fx * n.x() + calib_.left.cx),
                                   static_cast<float>(calib_.left.fy * n.y() + calib_.left.cy));
  }
  out->stats.keypoints = static_cast<uint32_t>(features_.keypoints.size());
  lap(&out->time.features_ms);

  for (KdSearcher& s : searchers_) s.ResetStats();
  MatchFeatures();
  out->stats.matches = static_cast<uint32_t>(matches_.size());
  for (const KdSearcher& s : searchers_) {
    out->stats.descriptors_compared += s.stats().descriptors_compared;
  }
  lap(&out->time.matching_ms);

  detections_.clear();
  planar_.clear();
  FindFaces();
  out->stats.votes = static_cast<uint32_t>(hough_.vote_count());
  out->stats.clusters = static_cast<uint32_t>(clusters_.size());
  out->stats.faces_2d = static_cast<uint32_t>(detections_.size());
  lap(&out->time.clustering_ms);

  stereo_matcher_.Reset(&calib_, left, right);
  parallel_(
      static_cast<int>(detections_.size()),
      [](void* self, int i) {
        static_cast<TextureRecognizer*>(self)->LocateFace(static_cast<size_t>(i));
      },
      this);
  for (const FaceDetection& d : detections_) {
    out->stats.faces_3d += d.posed ? 1 : 0;
    TextureFaceInfo info;
    info.face = d.face;
    info.matches = d.n_matches;
    info.mean_error_px = static_cast<float>(d.fit.mean_error_px);
    info.stereo_points = static_cast<uint16_t>(d.plane.points);
    info.plane_inliers = static_cast<uint16_t>(d.plane.inliers);
    info.posed = d.posed;
    const TexturedFace& face = db_.face(d.face);
    info.n_corners = face.n_corners;
    for (int k = 0; k < face.n_corners; ++k) {
      const Eigen::Vector2d px =
          ApplyHomography(d.fit.image_H_face, face.corners_ab_mm[k][0], face.corners_ab_mm[k][1]);
      info.corners_px[k][0] = static_cast<float>(px.x());
      info.corners_px[k][1] = static_cast<float>(px.y());
    }
    (void)out->faces.push_back(info);
  }
  lap(&out->time.stereo_ms);

  verifier_.Reset(&calib_, &db_, left, right);
  AssembleObjects(out);
  lap(&out->time.verify_ms);
  out->time.total_ms = MsSince(t0);
  return Status::Ok();
}

}  // namespace sh::texture
