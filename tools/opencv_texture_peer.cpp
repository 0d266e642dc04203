#include "tools/opencv_texture_peer.hpp"

#include <Eigen/Geometry>
#include <chrono>
#include <cmath>
#include <map>
#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>
#include <opencv2/features2d.hpp>
#include <opencv2/flann.hpp>

namespace sh::tools {
namespace {

double NowMs() {
  return std::chrono::duration<double, std::milli>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

cv::Mat Wrap(ConstGrayView v) {
  return cv::Mat(v.height, v.width, CV_8UC1, const_cast<uint8_t*>(v.data),
                 static_cast<size_t>(v.stride));
}

// Matches whose learnt features lie this close on one face are one physical point (learnt in
// several views); the ratio test compares against the nearest other point.
constexpr float kSamePointMm = 3.0f;
constexpr float kRatio = 0.8f;
constexpr int kNeighbours = 6;
constexpr int kMinFaceInliers = 8;
constexpr double kRansacPx = 3.0;

// OpenCV's camera matrix and distortion coefficients (k1 k2 p1 p2 k3) of a camera.
void CameraMatrices(const CameraIntrinsics& c, cv::Mat* K, cv::Mat* D) {
  *K = (cv::Mat_<double>(3, 3) << c.fx, 0, c.cx, 0, c.fy, c.cy, 0, 0, 1);
  *D = (cv::Mat_<double>(1, 5) << c.k1, c.k2, c.p1, c.p2, c.k3);
}

struct Learnt {
  int model, face;  // face: index over all printed faces
  Eigen::Vector3f model_mm;
  Eigen::Vector2f ab_mm;  // in the face frame
};

}  // namespace

struct OpenCvTexturePeer::Impl {
  cv::Ptr<cv::SIFT> sift = cv::SIFT::create();
  std::vector<Learnt> learnt;
  cv::Mat descriptors;  // CV_32F, one row per learnt feature
  std::unique_ptr<cv::flann::Index> index;
  std::vector<TexturedFace> faces;
};

OpenCvTexturePeer::OpenCvTexturePeer() : impl_(std::make_unique<Impl>()) {}
OpenCvTexturePeer::~OpenCvTexturePeer() = default;

size_t OpenCvTexturePeer::learnt_features() const { return impl_->learnt.size(); }

Status OpenCvTexturePeer::Learn(const std::vector<TexturedModel>& models,
                                const FeatureDbBuildOptions& options) {
  Impl& m = *impl_;
  m.learnt.clear();
  m.faces.clear();
  std::vector<cv::Mat> rows;
  for (size_t mi = 0; mi < models.size(); ++mi) {
    const TexturedModel& tm = models[mi];
    for (int fi = 0; fi < tm.model.n_faces; ++fi) {
      if (tm.texturing.faces[fi].material < 0) continue;
      Result<FaceLearning> learning = LearnFace(tm, fi, options);
      if (!learning.ok()) return learning.status();
      const int face_index = static_cast<int>(m.faces.size());
      m.faces.push_back(learning->face);
      const TexturedFace& face = learning->face;
      const Eigen::Vector3f o(face.origin_mm[0], face.origin_mm[1], face.origin_mm[2]);
      const Eigen::Vector3f a(face.axis_a[0], face.axis_a[1], face.axis_a[2]);
      const Eigen::Vector3f b(face.axis_b[0], face.axis_b[1], face.axis_b[2]);
      for (const LearningView& view : learning->views) {
        std::vector<cv::KeyPoint> kps;
        cv::Mat desc;
        m.sift->detectAndCompute(Wrap(view.image.view()), cv::noArray(), kps, desc);
        for (size_t k = 0; k < kps.size(); ++k) {
          // OpenCV's pixel centres sit at +0.5 of ours: its (0.5, 0.5) is our (0, 0).
          const Eigen::Vector2f p(kps[k].pt.x - 0.5f, kps[k].pt.y - 0.5f);
          if (!view.Inside(p, 0.5f * kps[k].size)) continue;
          const Eigen::Vector3f x = view.ModelPoint(face, p);
          m.learnt.push_back({static_cast<int>(mi), face_index, x,
                              Eigen::Vector2f((x - o).dot(a), (x - o).dot(b))});
          rows.push_back(desc.row(static_cast<int>(k)));
        }
      }
    }
  }
  if (rows.empty()) return Status::Error(StatusCode::kInvalidArgument, "peer: no features learnt");
  cv::vconcat(rows, m.descriptors);
  m.index = std::make_unique<cv::flann::Index>(m.descriptors, cv::flann::KDTreeIndexParams(4));
  return Status::Ok();
}

namespace {

// Left keypoint and learnt feature indices of matches, by face or model.
using MatchLists = std::map<int, std::vector<std::pair<int, int>>>;

// Matching: nearest learnt feature, kept when clearly closer than another physical point.
// Returns face -> (left keypoint, learnt).
MatchLists MatchByFace(const std::vector<Learnt>& learnt, cv::flann::Index& index,
                       const cv::Mat& dl) {
  MatchLists by_face;
  if (dl.empty()) return by_face;
  cv::Mat indices, dists;
  index.knnSearch(dl, indices, dists, kNeighbours, cv::flann::SearchParams(64));
  for (int i = 0; i < dl.rows; ++i) {
    const int best = indices.at<int>(i, 0);
    if (best < 0) continue;
    const Learnt& l0 = learnt[static_cast<size_t>(best)];
    float other = dists.at<float>(i, kNeighbours - 1);
    for (int j = 1; j < kNeighbours; ++j) {
      const int n = indices.at<int>(i, j);
      if (n < 0) break;
      const Learnt& lj = learnt[static_cast<size_t>(n)];
      if (lj.face != l0.face || (lj.model_mm - l0.model_mm).norm() > kSamePointMm) {
        other = dists.at<float>(i, j);
        break;
      }
    }
    // FLANN's L2 distances are squared.
    if (dists.at<float>(i, 0) < kRatio * kRatio * other) by_face[l0.face].push_back({i, best});
  }
  return by_face;
}

// A RANSAC homography per face (face millimetres to undistorted left pixels): the inliers of
// the faces that have enough, by model.
MatchLists InliersByModel(const std::vector<Learnt>& learnt, const std::vector<cv::KeyPoint>& kl,
                          const MatchLists& by_face, const cv::Mat& K1, const cv::Mat& D1) {
  MatchLists by_model;
  for (const auto& [face, list] : by_face) {
    if (static_cast<int>(list.size()) < kMinFaceInliers) continue;
    std::vector<cv::Point2f> src, dst_distorted, dst;
    for (const auto& [k, l] : list) {
      src.emplace_back(learnt[static_cast<size_t>(l)].ab_mm.x(),
                       learnt[static_cast<size_t>(l)].ab_mm.y());
      dst_distorted.push_back(kl[static_cast<size_t>(k)].pt - cv::Point2f(0.5f, 0.5f));
    }
    cv::undistortPoints(dst_distorted, dst, K1, D1, cv::noArray(), K1);
    std::vector<uchar> inlier;
    const cv::Mat H = cv::findHomography(src, dst, cv::RANSAC, kRansacPx, inlier);
    if (H.empty()) continue;
    int n = 0;
    for (uchar u : inlier) n += u ? 1 : 0;
    if (n < kMinFaceInliers) continue;
    const int model = learnt[static_cast<size_t>(list[0].second)].model;
    for (size_t i = 0; i < list.size(); ++i) {
      if (inlier[i]) by_model[model].push_back(list[i]);
    }
  }
  return by_model;
}

// The stereo rig as the pose step uses it: both cameras' matrices, the right camera's pose
// (OpenCV and as the essential matrix), and the right keypoints (normalised, undistorted) with
// their descriptors.
struct StereoRig {
  const StereoCalibration& calib;
  cv::Mat K1, D1, K2, D2, R, T;
  Eigen::Matrix3d E;
  std::vector<cv::Point2f> kr_norm;
  const cv::Mat& dr;

  StereoRig(const StereoCalibration& c, const std::vector<cv::KeyPoint>& kr,
            const cv::Mat& right_descriptors)
      : calib(c), dr(right_descriptors) {
    CameraMatrices(calib.left, &K1, &D1);
    CameraMatrices(calib.right, &K2, &D2);
    cv::eigen2cv(calib.right_R_left, R);
    cv::eigen2cv(calib.right_t_left_mm, T);
    // Right keypoints in normalised undistorted coordinates, once.
    std::vector<cv::Point2f> kr_px;
    kr_px.reserve(kr.size());
    for (const cv::KeyPoint& k : kr) kr_px.push_back(k.pt - cv::Point2f(0.5f, 0.5f));
    if (!kr_px.empty()) cv::undistortPoints(kr_px, kr_norm, K2, D2);
    const Eigen::Vector3d& t = calib.right_t_left_mm;
    Eigen::Matrix3d tx;
    tx << 0, -t.z(), t.y(), t.z(), 0, -t.x(), -t.y(), t.x(), 0;
    E = tx * calib.right_R_left;
  }

  // The right keypoint matching descriptor q near the epipolar line of the normalised left
  // point p (descriptor ratio test among the candidates), or -1.
  int RightMatch(const cv::Point2f& p, const cv::Mat& q) const {
    const Eigen::Vector3d line = E * Eigen::Vector3d(p.x, p.y, 1.0);
    const double scale = line.head<2>().norm();
    if (!(scale > 0)) return -1;
    double best = 1e30, second = 1e30;
    int best_j = -1;
    for (size_t j = 0; j < kr_norm.size(); ++j) {
      const double dist = std::fabs(line.x() * kr_norm[j].x + line.y() * kr_norm[j].y + line.z()) /
                          scale * calib.right.fx;
      if (dist > 2.0) continue;
      const double d = cv::norm(q, dr.row(static_cast<int>(j)), cv::NORM_L2SQR);
      if (d < best) {
        second = best;
        best = d;
        best_j = static_cast<int>(j);
      } else if (d < second) {
        second = d;
      }
    }
    if (best_j < 0 || best > kRatio * kRatio * second) return -1;
    return best_j;
  }
};

// Refines out's pose (Re, te: its solvePnP pose) by stereo: the left points ln matched to the
// right points rn, triangulated, kept when near the pose, and the model points fitted to them.
void FitStereo(const StereoRig& rig, const std::vector<cv::Point2f>& ln,
               const std::vector<cv::Point2f>& rn, const std::vector<Eigen::Vector3d>& model_pts,
               const Eigen::Matrix3d& Re, const Eigen::Vector3d& te, PeerObject* out) {
  cv::Mat P1 = cv::Mat::eye(3, 4, CV_64F), P2(3, 4, CV_64F), X;
  rig.R.copyTo(P2(cv::Rect(0, 0, 3, 3)));
  rig.T.copyTo(P2(cv::Rect(3, 0, 1, 3)));
  cv::triangulatePoints(P1, P2, ln, rn, X);
  Eigen::Matrix3Xd src(3, 0), dst(3, 0);
  for (int c = 0; c < X.cols; ++c) {
    const double w = X.at<float>(3, c);
    if (std::fabs(w) < 1e-12) continue;
    const Eigen::Vector3d p(X.at<float>(0, c) / w, X.at<float>(1, c) / w, X.at<float>(2, c) / w);
    const Eigen::Vector3d predicted = Re * model_pts[static_cast<size_t>(c)] + te;
    if ((p - predicted).norm() > 10.0) continue;
    src.conservativeResize(3, src.cols() + 1);
    dst.conservativeResize(3, dst.cols() + 1);
    src.col(src.cols() - 1) = model_pts[static_cast<size_t>(c)];
    dst.col(dst.cols() - 1) = p;
  }
  if (src.cols() >= 6) {
    const Eigen::Matrix4d fit = Eigen::umeyama(src, dst, false);
    out->cam_T_model.R = fit.topLeftCorner<3, 3>().cast<float>();
    out->cam_T_model.t_mm = fit.topRightCorner<3, 1>().cast<float>();
    out->stereo_points = static_cast<int>(src.cols());
  }
}

// The pose of `model` from its inlier matches `list`: solvePnP, then stereo. False when
// solvePnP fails.
bool ModelPose(const std::vector<Learnt>& learnt, const std::vector<cv::KeyPoint>& kl,
               const cv::Mat& dl, const StereoRig& rig, int model,
               const std::vector<std::pair<int, int>>& list, PeerObject* object) {
  std::vector<cv::Point3f> obj;
  std::vector<cv::Point2f> img;
  for (const auto& [k, l] : list) {
    const Eigen::Vector3f& x = learnt[static_cast<size_t>(l)].model_mm;
    obj.emplace_back(x.x(), x.y(), x.z());
    img.push_back(kl[static_cast<size_t>(k)].pt - cv::Point2f(0.5f, 0.5f));
  }
  cv::Mat rvec, tvec;
  if (!cv::solvePnP(obj, img, rig.K1, rig.D1, rvec, tvec, false, cv::SOLVEPNP_ITERATIVE)) {
    return false;
  }
  cv::Mat Rm;
  cv::Rodrigues(rvec, Rm);
  PeerObject out;
  out.model = model;
  Eigen::Matrix3d Re;
  Eigen::Vector3d te;
  cv::cv2eigen(Rm, Re);
  cv::cv2eigen(tvec, te);
  out.cam_T_model.R = Re.cast<float>();
  out.cam_T_model.t_mm = te.cast<float>();
  out.matches = static_cast<int>(list.size());
  // Stereo: each inlier's right match near its epipolar line, triangulated, kept when near the
  // solvePnP pose.
  std::vector<cv::Point2f> ln, rn;
  std::vector<Eigen::Vector3d> model_pts;
  std::vector<cv::Point2f> img_norm;
  cv::undistortPoints(img, img_norm, rig.K1, rig.D1);
  for (size_t i = 0; i < list.size(); ++i) {
    const int best_j = rig.RightMatch(img_norm[i], dl.row(list[i].first));
    if (best_j < 0) continue;
    ln.push_back(img_norm[i]);
    rn.push_back(rig.kr_norm[static_cast<size_t>(best_j)]);
    const Eigen::Vector3f& x = learnt[static_cast<size_t>(list[i].second)].model_mm;
    model_pts.push_back(x.cast<double>());
  }
  if (ln.size() >= 6) FitStereo(rig, ln, rn, model_pts, Re, te, &out);
  *object = out;
  return true;
}

}  // namespace

Status OpenCvTexturePeer::Process(const StereoCalibration& calib, ConstGrayView left,
                                  ConstGrayView right, std::vector<PeerObject>* objects,
                                  PeerTimings* time) {
  Impl& m = *impl_;
  objects->clear();
  *time = {};
  if (!m.index) return Status::Error(StatusCode::kFailedPrecondition, "peer: nothing learnt");
  const double t0 = NowMs();
  std::vector<cv::KeyPoint> kl, kr;
  cv::Mat dl, dr;
  m.sift->detectAndCompute(Wrap(left), cv::noArray(), kl, dl);
  m.sift->detectAndCompute(Wrap(right), cv::noArray(), kr, dr);
  const double t1 = NowMs();
  time->features_ms = static_cast<float>(t1 - t0);
  const MatchLists by_face = MatchByFace(m.learnt, *m.index, dl);
  const double t2 = NowMs();
  time->matching_ms = static_cast<float>(t2 - t1);
  cv::Mat K1, D1;
  CameraMatrices(calib.left, &K1, &D1);
  const MatchLists by_model = InliersByModel(m.learnt, kl, by_face, K1, D1);
  const double t3 = NowMs();
  time->clustering_ms = static_cast<float>(t3 - t2);
  // Pose per model: solvePnP, then stereo.
  const StereoRig rig(calib, kr, dr);
  for (const auto& [model, list] : by_model) {
    if (list.size() < 6) continue;
    PeerObject out;
    if (ModelPose(m.learnt, kl, dl, rig, model, list, &out)) objects->push_back(out);
  }
  const double t4 = NowMs();
  time->stereo_ms = static_cast<float>(t4 - t3);
  time->total_ms = static_cast<float>(t4 - t0);
  return Status::Ok();
}

}  // namespace sh::tools
