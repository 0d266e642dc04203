#include "tools/handeye.hpp"

#include <Eigen/Geometry>
#include <cmath>
#include <cstdlib>
#include <opencv2/calib3d.hpp>
#include <sstream>

#include "recog/camera/camera_model.hpp"
#include "recog/stereo/triangulation.hpp"

namespace sh::tools {
namespace {

using Iso = Eigen::Isometry3d;

Iso ToIso(const RigidTransform& T) {
  Iso iso = Iso::Identity();
  iso.linear() = T.R.cast<double>();
  iso.translation() = T.t_mm.cast<double>();
  return iso;
}

RigidTransform FromIso(const Iso& iso) {
  RigidTransform T;
  T.R = iso.linear().cast<float>();
  T.t_mm = iso.translation().cast<float>();
  return T;
}

double AngleDeg(const Eigen::Matrix3d& R) { return Eigen::AngleAxisd(R).angle() * 180.0 / M_PI; }

// Mean of rigid transforms: quaternions on one hemisphere averaged and normalised (fine for the
// nearly equal rotations of a calibration), translations averaged.
Iso MeanTransform(const std::vector<Iso>& poses) {
  Eigen::Vector4d q_sum = Eigen::Vector4d::Zero();
  Eigen::Vector3d t_sum = Eigen::Vector3d::Zero();
  const Eigen::Quaterniond first(poses[0].linear());
  for (const Iso& p : poses) {
    Eigen::Quaterniond q(p.linear());
    if (q.dot(first) < 0) q.coeffs() = -q.coeffs();
    q_sum += q.coeffs();
    t_sum += p.translation();
  }
  Iso mean = Iso::Identity();
  mean.linear() = Eigen::Quaterniond(q_sum.normalized()).toRotationMatrix();
  mean.translation() = t_sum / static_cast<double>(poses.size());
  return mean;
}

cv::Mat ToCvR(const Eigen::Matrix3d& R) {
  cv::Mat m(3, 3, CV_64F);
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) m.at<double>(r, c) = R(r, c);
  }
  return m;
}

cv::Mat ToCvT(const Eigen::Vector3d& t) {
  cv::Mat m(3, 1, CV_64F);
  for (int r = 0; r < 3; ++r) m.at<double>(r, 0) = t[r];
  return m;
}

// Pixel residuals (left u, v, right u, v per corner) of the board grid at `pose` (left camera).
Eigen::VectorXd ReprojectionResiduals(const StereoCalibration& calib,
                                      const std::vector<cv::Point2f>& left,
                                      const std::vector<cv::Point2f>& right,
                                      const Eigen::Matrix3Xd& grid, const Iso& pose) {
  const long n = grid.cols();
  Eigen::VectorXd r(4 * n);
  for (long i = 0; i < n; ++i) {
    const Eigen::Vector3d x_left = pose * grid.col(i);
    const Eigen::Vector3d x_right = calib.right_R_left * x_left + calib.right_t_left_mm;
    Eigen::Vector2d pl = Eigen::Vector2d::Zero(), pr = Eigen::Vector2d::Zero();
    (void)ProjectToPixel(calib.left, x_left, &pl);
    (void)ProjectToPixel(calib.right, x_right, &pr);
    r.segment<4>(4 * i) << pl.x() - left[i].x, pl.y() - left[i].y, pr.x() - right[i].x,
        pr.y() - right[i].y;
  }
  return r;
}

// Gauss-Newton on the six pose parameters (rotation vector and translation increments applied
// on the left), numerical Jacobian: a handful of iterations from the triangulated start.
void RefineByReprojection(const StereoCalibration& calib, const std::vector<cv::Point2f>& left,
                          const std::vector<cv::Point2f>& right, const Eigen::Matrix3Xd& grid,
                          Iso* pose) {
  const auto perturbed = [](const Iso& p, const Eigen::Matrix<double, 6, 1>& d) {
    Iso q = p;
    if (d.head<3>().norm() > 0) {
      q.linear() = Eigen::AngleAxisd(d.head<3>().norm(), d.head<3>().normalized()) * p.linear();
    }
    q.translation() += d.tail<3>();
    return q;
  };
  Eigen::VectorXd r = ReprojectionResiduals(calib, left, right, grid, *pose);
  for (int iteration = 0; iteration < 10; ++iteration) {
    Eigen::MatrixXd J(r.size(), 6);
    for (int k = 0; k < 6; ++k) {
      Eigen::Matrix<double, 6, 1> d = Eigen::Matrix<double, 6, 1>::Zero();
      d[k] = k < 3 ? 1e-6 : 1e-4;  // radians, millimetres
      J.col(k) = (ReprojectionResiduals(calib, left, right, grid, perturbed(*pose, d)) - r) / d[k];
    }
    const Eigen::Matrix<double, 6, 1> step = (J.transpose() * J).ldlt().solve(-J.transpose() * r);
    const Iso next = perturbed(*pose, step);
    const Eigen::VectorXd r_next = ReprojectionResiduals(calib, left, right, grid, next);
    if (!step.allFinite() || r_next.squaredNorm() >= r.squaredNorm()) break;
    *pose = next;
    r = r_next;
    if (step.norm() < 1e-9) break;
  }
}

}  // namespace

bool ParseRotationFormat(const char* text, RotationFormat* format) {
  const std::string s = text;
  if (s == "quat") {
    *format = RotationFormat::kQuaternion;
  } else if (s == "rotvec") {
    *format = RotationFormat::kRotationVector;
  } else if (s == "zyx") {
    *format = RotationFormat::kZyxEuler;
  } else {
    return false;
  }
  return true;
}

Result<std::vector<RigidTransform>> ParseRobotPoses(const std::string& text,
                                                    RotationFormat format) {
  const size_t rotation_values = format == RotationFormat::kQuaternion ? 4 : 3;
  std::vector<RigidTransform> poses;
  std::istringstream lines(text);
  std::string line;
  int number = 0;
  bool header_allowed = true;
  while (std::getline(lines, line)) {
    ++number;
    const size_t hash = line.find('#');
    if (hash != std::string::npos) line.resize(hash);
    for (char& c : line) {
      if (c == ',' || c == ';' || c == '\t' || c == '\r') c = ' ';
    }
    std::istringstream fields(line);
    std::vector<double> v;
    std::string field;
    bool numeric = true;
    while (fields >> field) {
      char* end = nullptr;
      const double x = std::strtod(field.c_str(), &end);
      if (end == field.c_str() || *end != '\0' || !std::isfinite(x)) {
        numeric = false;
        break;
      }
      v.push_back(x);
    }
    if (v.empty() && numeric) continue;  // blank or comment
    if (!numeric) {
      if (header_allowed && poses.empty()) {  // a header line naming the columns
        header_allowed = false;
        continue;
      }
      return Status::Error(StatusCode::kInvalidArgument,
                           "robot poses line %d: '%s' is not a number", number, field.c_str());
    }
    if (v.size() != 3 + rotation_values) {
      return Status::Error(StatusCode::kInvalidArgument,
                           "robot poses line %d: %zu numbers, expected x y z and %zu for the "
                           "rotation",
                           number, v.size(), rotation_values);
    }
    Eigen::Matrix3d R;
    if (format == RotationFormat::kQuaternion) {
      const Eigen::Quaterniond q(v[3], v[4], v[5], v[6]);
      if (std::fabs(q.norm() - 1.0) > 1e-3) {
        return Status::Error(StatusCode::kInvalidArgument,
                             "robot poses line %d: quaternion norm %.4f is not 1 (w x y z)", number,
                             q.norm());
      }
      R = q.normalized().toRotationMatrix();
    } else if (format == RotationFormat::kRotationVector) {
      const Eigen::Vector3d r = Eigen::Vector3d(v[3], v[4], v[5]) * (M_PI / 180.0);
      R = r.norm() > 0 ? Eigen::AngleAxisd(r.norm(), r.normalized()).toRotationMatrix()
                       : Eigen::Matrix3d::Identity();
    } else {
      const double d = M_PI / 180.0;
      R = (Eigen::AngleAxisd(v[3] * d, Eigen::Vector3d::UnitZ()) *
           Eigen::AngleAxisd(v[4] * d, Eigen::Vector3d::UnitY()) *
           Eigen::AngleAxisd(v[5] * d, Eigen::Vector3d::UnitX()))
              .toRotationMatrix();
    }
    Iso pose = Iso::Identity();
    pose.linear() = R;
    pose.translation() = Eigen::Vector3d(v[0], v[1], v[2]);
    poses.push_back(FromIso(pose));
    header_allowed = false;
  }
  return poses;
}

Result<RigidTransform> BoardPoseFromStereo(const StereoCalibration& calib,
                                           const std::vector<cv::Point2f>& left,
                                           const std::vector<cv::Point2f>& right, cv::Size board,
                                           double square_mm, double* fit_max_mm) {
  const int n = board.width * board.height;
  if (static_cast<int>(left.size()) != n || static_cast<int>(right.size()) != n) {
    return Status::Error(StatusCode::kInvalidArgument, "expected %d corners per image", n);
  }
  Eigen::Matrix3Xd grid(3, n), seen(3, n);
  for (int i = 0; i < n; ++i) {
    RayMidpoint m;
    if (!TriangulatePixels(calib, Eigen::Vector2d(left[i].x, left[i].y),
                           Eigen::Vector2d(right[i].x, right[i].y), &m)) {
      return Status::Error(
          StatusCode::kInvalidArgument,
          "a corner's rays are parallel: is the calibration right for the images?");
    }
    seen.col(i) = m.p_mm;
    const int column = i % board.width, row = i / board.width;  // OpenCV's row-major order
    grid.col(i) = Eigen::Vector3d(column * square_mm, row * square_mm, 0);
  }
  const Eigen::Matrix4d fit = Eigen::umeyama(grid, seen, /*with_scaling=*/false);
  Iso pose = Iso::Identity();
  pose.linear() = fit.topLeftCorner<3, 3>();
  pose.translation() = fit.topRightCorner<3, 1>();
  double worst = 0;
  for (int i = 0; i < n; ++i) worst = std::max(worst, (pose * grid.col(i) - seen.col(i)).norm());
  *fit_max_mm = worst;
  // Triangulated points err mostly in depth; the pose that best explains the corners in both
  // images weighs every measurement by what it determines.
  RefineByReprojection(calib, left, right, grid, &pose);
  return FromIso(pose);
}

Result<HandEyeSolution> SolveHandEye(const std::vector<RigidTransform>& base_T_flange,
                                     const std::vector<RigidTransform>& camera_T_board,
                                     bool eye_in_hand, int method, double board_width_mm,
                                     double board_height_mm) {
  const size_t n = base_T_flange.size();
  if (n != camera_T_board.size()) {
    return Status::Error(StatusCode::kInvalidArgument, "%zu robot poses but %zu board poses", n,
                         camera_T_board.size());
  }
  if (n < 3) {
    return Status::Error(StatusCode::kInvalidArgument,
                         "%zu stations: at least 3 are needed (better 10 or more)", n);
  }
  // The motions must turn about at least two different axes, else the solution is not unique.
  double largest_spread = 0;
  const Iso flange0 = ToIso(base_T_flange[0]);
  for (size_t i = 1; i < n; ++i) {
    for (size_t j = 1; j < n; ++j) {
      const Eigen::AngleAxisd a((flange0.inverse() * ToIso(base_T_flange[i])).linear());
      const Eigen::AngleAxisd b((flange0.inverse() * ToIso(base_T_flange[j])).linear());
      if (a.angle() < 1e-3 || b.angle() < 1e-3) continue;
      largest_spread =
          std::max(largest_spread, std::acos(std::min(1.0, std::fabs(a.axis().dot(b.axis())))));
    }
  }
  if (largest_spread < 5.0 * M_PI / 180.0) {
    return Status::Error(StatusCode::kInvalidArgument,
                         "the robot's rotations between stations are all about one axis (or "
                         "none): turn the flange about at least two different axes");
  }
  std::vector<cv::Mat> R_gripper, t_gripper, R_target, t_target;
  for (size_t i = 0; i < n; ++i) {
    // Eye-to-hand: OpenCV's eye-in-hand equations with the inverted robot poses give the
    // camera's pose in the base (the documented use of calibrateHandEye for fixed cameras).
    const Iso g = eye_in_hand ? ToIso(base_T_flange[i]) : ToIso(base_T_flange[i]).inverse();
    R_gripper.push_back(ToCvR(g.linear()));
    t_gripper.push_back(ToCvT(g.translation()));
    const Iso c = ToIso(camera_T_board[i]);
    R_target.push_back(ToCvR(c.linear()));
    t_target.push_back(ToCvT(c.translation()));
  }
  cv::Mat R_x, t_x;
  cv::calibrateHandEye(R_gripper, t_gripper, R_target, t_target, R_x, t_x,
                       static_cast<cv::HandEyeCalibrationMethod>(method));
  Iso X = Iso::Identity();
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) X.linear()(r, c) = R_x.at<double>(r, c);
    X.translation()[r] = t_x.at<double>(r, 0);
  }
  if (!X.matrix().allFinite()) {
    return Status::Error(StatusCode::kInternal, "calibrateHandEye gave no finite solution");
  }

  // The other unknown of the chain, averaged over the stations, then every station's board
  // pose predicted through the chain.
  std::vector<Iso> other(n);
  for (size_t i = 0; i < n; ++i) {
    const Iso B = ToIso(base_T_flange[i]);
    const Iso C = ToIso(camera_T_board[i]);
    other[i] = eye_in_hand ? B * X * C : B.inverse() * X * C;  // base_T_board / flange_T_board
  }
  const Iso Y = MeanTransform(other);
  HandEyeSolution s;
  s.robot_T_camera = FromIso(X);
  s.other = FromIso(Y);
  const Eigen::Vector3d corners[4] = {
      Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(board_width_mm, 0, 0),
      Eigen::Vector3d(0, board_height_mm, 0), Eigen::Vector3d(board_width_mm, board_height_mm, 0)};
  double sum_mm = 0, sum_deg = 0;
  for (size_t i = 0; i < n; ++i) {
    const Iso B = ToIso(base_T_flange[i]);
    const Iso measured = ToIso(camera_T_board[i]);
    const Iso predicted = eye_in_hand ? X.inverse() * B.inverse() * Y : X.inverse() * B * Y;
    double mm = 0;
    for (const Eigen::Vector3d& p : corners)
      mm = std::max(mm, (predicted * p - measured * p).norm());
    const double deg = AngleDeg(predicted.linear().transpose() * measured.linear());
    s.residual_mm.push_back(mm);
    s.residual_deg.push_back(deg);
    sum_mm += mm * mm;
    sum_deg += deg * deg;
    s.max_mm = std::max(s.max_mm, mm);
    s.max_deg = std::max(s.max_deg, deg);
  }
  s.rms_mm = std::sqrt(sum_mm / static_cast<double>(n));
  s.rms_deg = std::sqrt(sum_deg / static_cast<double>(n));
  return s;
}

}  // namespace sh::tools
