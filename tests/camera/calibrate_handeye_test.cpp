// `stereohash calibrate-handeye` on synthetic robot stations rendered by the project's renderer
// (ray cast through the calibration, shading, shadows, noise): a chessboard of thin dark tiles
// on a white plate, carried by the robot in front of fixed cameras (eye-to-hand) or lying on the
// table under cameras on the flange (eye-in-hand). The transform the tool writes must agree with
// the one the stations were made from within 0.5 mm and 0.1 degrees.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <memory>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "hal/sim/image_files.hpp"
#include "hal/sim/world/renderer.hpp"
#include "recog/camera/calibration_yaml.hpp"
#include "recog/camera/handeye_yaml.hpp"
#include "recog/model/obj_model.hpp"
#include "tests/support/temp_dir.hpp"

namespace sh {
namespace {

constexpr int kCols = 5, kRows = 4;  // inner corners; different parity: no half-turn ambiguity
constexpr double kSquareMm = 20.0;
constexpr int kStations = 8;

using Iso = Eigen::Isometry3d;

Iso Pose(const Eigen::Vector3d& t, const Eigen::Vector3d& rotvec_deg) {
  Iso p = Iso::Identity();
  const Eigen::Vector3d r = rotvec_deg * (M_PI / 180.0);
  if (r.norm() > 0) p.linear() = Eigen::AngleAxisd(r.norm(), r.normalized()).toRotationMatrix();
  p.translation() = t;
  return p;
}

RigidTransform ToRigid(const Iso& p) {
  RigidTransform T;
  T.R = p.linear().cast<float>();
  T.t_mm = p.translation().cast<float>();
  return T;
}

// A camera at `eye` looking at `target` (OpenCV axes: z forward, y down), rolled about its axis.
Iso LookAt(const Eigen::Vector3d& eye, const Eigen::Vector3d& target, double roll_deg) {
  const Eigen::Vector3d z = (target - eye).normalized();
  Eigen::Vector3d x = z.cross(Eigen::Vector3d::UnitZ());
  if (x.norm() < 1e-6) x = Eigen::Vector3d::UnitX();
  x.normalize();
  const Eigen::Vector3d y = z.cross(x);
  Iso p = Iso::Identity();
  p.linear() << x, y, z;
  p.linear() = p.linear() * Eigen::AngleAxisd(roll_deg * M_PI / 180.0, Eigen::Vector3d::UnitZ());
  p.translation() = eye;
  return p;
}

// An axis-aligned box from (x0, y0, z0) to (x1, y1, z1) as OBJ text (faces wound outwards).
std::string BoxObj(double x0, double y0, double z0, double x1, double y1, double z1) {
  std::ostringstream o;
  const double xs[2] = {x0, x1}, ys[2] = {y0, y1}, zs[2] = {z0, z1};
  for (int k = 0; k < 8; ++k)
    o << "v " << xs[k & 1] << " " << ys[(k >> 1) & 1] << " " << zs[k >> 2] << "\n";
  o << "f 1 3 4 2\nf 5 6 8 7\nf 1 2 6 5\nf 3 7 8 4\nf 1 5 7 3\nf 2 4 8 6\n";
  return o.str();
}

class HandEyeRig {
 public:
  HandEyeRig() {
    for (CameraIntrinsics* c : {&calib_.left, &calib_.right}) {
      c->width = 756;
      c->height = 581;
      c->fx = c->fy = 1136.4;
      c->cx = 377.5;
      c->cy = 290.0;
    }
    // Converged rig: the optical axes meet about 450 mm out, so both cameras see the board.
    calib_.right_R_left = Eigen::AngleAxisd(0.26, Eigen::Vector3d::UnitY()).toRotationMatrix();
    calib_.right_t_left_mm = Eigen::Vector3d(-118.0, -2.0, 15.0);
    // Board frame: origin at the plate's top centre, z up out of the printed face. Plate 2 mm
    // thick with a one-square white margin; dark tiles 0.05 mm proud of it.
    const double half_w = (kCols + 1) * kSquareMm / 2 + kSquareMm;
    const double half_h = (kRows + 1) * kSquareMm / 2 + kSquareMm;
    const std::string plate = BoxObj(-half_w, -half_h, -2.0, half_w, half_h, 0.0);
    const std::string tile = BoxObj(0, 0, 0, kSquareMm, kSquareMm, 0.05);
    const Result<Model> p = ParseObjModel(plate.data(), plate.size(), "plate");
    const Result<Model> t = ParseObjModel(tile.data(), tile.size(), "tile");
    EXPECT_TRUE(p.ok() && t.ok());
    models_[0] = *p;
    models_[1] = *t;
    pixels_[0].resize(size_t{756} * 581);
    pixels_[1].resize(size_t{756} * 581);
  }

  // Renders the board at table_T_board seen by a left camera at table_T_camera.
  void Render(const Iso& table_T_board, const Iso& table_T_camera, const std::string& left,
              const std::string& right, uint64_t seed) {
    render::RenderScene scene;
    scene.background = render::Background::kDark;
    scene.left_T_table = ToRigid(table_T_camera.inverse());
    scene.noise_sigma = 1.0f;
    scene.seed = seed;
    scene.lights[0].position_table_mm = Eigen::Vector3f(-300, -200, 900);
    scene.lights[1].position_table_mm = Eigen::Vector3f(250, 300, 800);
    render::SceneObject plate;
    plate.model_index = 0;
    plate.table_T_model = ToRigid(table_T_board);
    plate.albedo = 0.85f;
    (void)scene.objects.push_back(plate);
    for (int r = 0; r < kRows + 1; ++r) {
      for (int c = 0; c < kCols + 1; ++c) {
        if ((r + c) % 2 != 0) continue;
        render::SceneObject tile;
        tile.model_index = 1;
        const Eigen::Vector3d at(c * kSquareMm - (kCols + 1) * kSquareMm / 2,
                                 r * kSquareMm - (kRows + 1) * kSquareMm / 2, 0);
        tile.table_T_model = ToRigid(table_T_board * Pose(at, Eigen::Vector3d::Zero()));
        tile.albedo = 0.06f;
        ASSERT_TRUE(scene.objects.push_back(tile));
      }
    }
    GrayView views[2] = {GrayView{pixels_[0].data(), 756, 581, 756},
                         GrayView{pixels_[1].data(), 756, 581, 756}};
    ASSERT_TRUE(render::RenderStereo(scene, models_, 2, calib_, views[0], views[1]).ok());
    ASSERT_TRUE(hal::WritePng(left.c_str(), views[0]).ok());
    ASSERT_TRUE(hal::WritePng(right.c_str(), views[1]).ok());
  }

  const StereoCalibration& calib() const { return calib_; }

 private:
  StereoCalibration calib_;
  Model models_[2];
  std::vector<uint8_t> pixels_[2];
};

class CalibrateHandEyeTool : public ::testing::Test {
 protected:
  void SetUp() override {
    ASSERT_TRUE(temp_.ok());
    char text[8192];
    const Result<size_t> n = WriteCalibrationYaml(rig_.calib(), text, sizeof(text));
    ASSERT_TRUE(n.ok());
    std::ofstream(dir_ + "/calib.yaml") << std::string(text, *n);
  }
  std::string Station(const char* side, int i) const {
    char name[64];
    std::snprintf(name, sizeof(name), "/%s%02d.png", side, i);
    return dir_ + name;
  }

  // Writes the CSV (x y z and the rotation as `rotation` says) and runs the tool; returns the
  // hand-eye file.
  HandEye Run(const std::vector<Iso>& base_T_flange, const char* mode, std::string* output,
              const std::string& rotation = "quat") {
    std::ofstream csv(dir_ + "/robot.csv");
    csv << "# robot stations\nx,y,z,rotation\n";
    csv.precision(12);
    for (const Iso& p : base_T_flange) {
      csv << p.translation().x() << ";" << p.translation().y() << ";" << p.translation().z();
      if (rotation == "quat") {
        const Eigen::Quaterniond q(p.linear());
        csv << ";" << q.w() << ";" << q.x() << ";" << q.y() << ";" << q.z() << "\n";
      } else if (rotation == "rotvec") {
        const Eigen::AngleAxisd a(p.linear());
        const Eigen::Vector3d r = a.axis() * a.angle() * 180.0 / M_PI;
        csv << ";" << r.x() << ";" << r.y() << ";" << r.z() << "\n";
      } else {  // zyx: R = Rz(A) Ry(B) Rx(C)
        const Eigen::Matrix3d& R = p.linear();
        const double b = std::atan2(-R(2, 0), std::hypot(R(0, 0), R(1, 0)));
        const double a = std::atan2(R(1, 0), R(0, 0)), c = std::atan2(R(2, 1), R(2, 2));
        csv << ";" << a * 180 / M_PI << ";" << b * 180 / M_PI << ";" << c * 180 / M_PI << "\n";
      }
    }
    csv.close();
    const std::string command = std::string(STEREOHASH_EXE) + " calibrate-handeye --calib " + dir_ +
                                "/calib.yaml --poses " + dir_ + "/robot.csv --left '" + dir_ +
                                "/left*.png' --right '" + dir_ +
                                "/right*.png' --board 5x4 --square-mm 20 " + mode + " --rotation " +
                                rotation + " --out " + dir_ + "/handeye.yaml 2>&1";
    FILE* pipe = popen(command.c_str(), "r");
    char buf[512];
    while (pipe != nullptr && std::fgets(buf, sizeof(buf), pipe) != nullptr) *output += buf;
    const int status = pipe != nullptr ? pclose(pipe) : -1;
    EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << *output;
    std::ifstream in(dir_ + "/handeye.yaml");
    const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    const Result<HandEye> h = ParseHandEyeYaml(text.data(), text.size());
    EXPECT_TRUE(h.ok()) << h.status().message() << "\n" << *output;
    return h.ok() ? *h : HandEye();
  }

  static void ExpectClose(const HandEye& h, const Iso& truth, const std::string& output) {
    const Eigen::Vector3d t = h.robot_T_camera.t_mm.cast<double>();
    const Eigen::Matrix3d R = h.robot_T_camera.R.cast<double>();
    const double dt = (t - truth.translation()).norm();
    const double dr = Eigen::AngleAxisd(R.transpose() * truth.linear()).angle() * 180.0 / M_PI;
    std::printf(
        "recovered transform: %.3f mm, %.4f deg from the truth; residual rms %.3f mm "
        "%.4f deg\n",
        dt, dr, h.residual_rms_mm, h.residual_rms_deg);
    EXPECT_LT(dt, 0.5) << output;
    EXPECT_LT(dr, 0.1) << output;
    EXPECT_EQ(h.poses, kStations) << output;
  }

  HandEyeRig rig_;
  const sh::testing::TempDir temp_{"handeye"};
  const std::string& dir_ = temp_.path();
  // The robot's base in the table (world) frame of the renderer.
  const Iso table_T_base_ = Pose(Eigen::Vector3d(-420, 60, -25), Eigen::Vector3d(0, 0, 90));
};

TEST_F(CalibrateHandEyeTool, EyeToHandRecoversTheCameraInTheBase) {
  // Cameras fixed 550 mm over the work area; the board on the flange, 80 mm out.
  const Iso table_T_camera = LookAt(Eigen::Vector3d(40, -160, 560), Eigen::Vector3d(0, 0, 120), 8);
  const Iso flange_T_board = Pose(Eigen::Vector3d(10, -20, 80), Eigen::Vector3d(4, -3, 30));
  const Iso base_T_camera = table_T_base_.inverse() * table_T_camera;
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1, 1);
  std::vector<Iso> base_T_flange;
  for (int i = 0; i < kStations; ++i) {
    // The board faces the cameras, tilted up to 30 degrees about two axes, spun up to 60.
    const Eigen::Vector3d centre(40 * u(rng), 40 * u(rng), 120 + 30 * u(rng));
    Iso table_T_board = LookAt(centre, table_T_camera.translation(), 0);  // z towards the camera
    table_T_board.linear() =
        table_T_board.linear() *
        (Eigen::AngleAxisd(30 * M_PI / 180 * u(rng), Eigen::Vector3d::UnitX()) *
         Eigen::AngleAxisd(30 * M_PI / 180 * u(rng), Eigen::Vector3d::UnitY()) *
         Eigen::AngleAxisd(60 * M_PI / 180 * u(rng), Eigen::Vector3d::UnitZ()))
            .toRotationMatrix();
    base_T_flange.push_back(table_T_base_.inverse() * table_T_board * flange_T_board.inverse());
    rig_.Render(table_T_board, table_T_camera, Station("left", i), Station("right", i), 100 + i);
  }
  std::string output;
  const HandEye h = Run(base_T_flange, "--eye-to-hand", &output);
  EXPECT_FALSE(h.eye_in_hand);
  ExpectClose(h, base_T_camera, output);
  // The same stations written as a rotation vector or as Z-Y-X angles give the same answer.
  for (const char* rotation : {"rotvec", "zyx"}) {
    output.clear();
    const HandEye again = Run(base_T_flange, "--eye-to-hand", &output, rotation);
    EXPECT_LT((again.robot_T_camera.t_mm - h.robot_T_camera.t_mm).norm(), 1e-3f) << rotation;
    EXPECT_LT((again.robot_T_camera.R - h.robot_T_camera.R).norm(), 1e-5f) << rotation;
  }
}

TEST_F(CalibrateHandEyeTool, EyeInHandRecoversTheCameraOnTheFlange) {
  // The board lies on the table; the cameras ride on the flange.
  const Iso table_T_board = Pose(Eigen::Vector3d(15, -10, 2), Eigen::Vector3d(0, 0, 12));
  const Iso flange_T_camera = Pose(Eigen::Vector3d(60, -5, 110), Eigen::Vector3d(2, 3, -90));
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> u(-1, 1);
  std::vector<Iso> base_T_flange;
  for (int i = 0; i < kStations; ++i) {
    const Eigen::Vector3d eye(120 * u(rng), -100 + 120 * u(rng), 380 + 60 * u(rng));
    const Iso table_T_camera =
        LookAt(eye, table_T_board.translation() + Eigen::Vector3d(20 * u(rng), 20 * u(rng), 0),
               70 * u(rng));
    base_T_flange.push_back(table_T_base_.inverse() * table_T_camera * flange_T_camera.inverse());
    rig_.Render(table_T_board, table_T_camera, Station("left", i), Station("right", i), 200 + i);
  }
  std::string output;
  const HandEye h = Run(base_T_flange, "--eye-in-hand", &output);
  EXPECT_TRUE(h.eye_in_hand);
  ExpectClose(h, flange_T_camera, output);
}

TEST_F(CalibrateHandEyeTool, BadInputIsRefusedNamingTheProblem) {
  std::ofstream(dir_ + "/robot.csv") << "x y z qw qx qy qz\n1 2 3 1 0 0 0\n4 5 6 0.5 0 0\n";
  const std::string base = std::string(STEREOHASH_EXE) + " calibrate-handeye --calib " + dir_ +
                           "/calib.yaml --poses " + dir_ + "/robot.csv --left '" + dir_ +
                           "/left*.png' --right '" + dir_ + "/right*.png' --board 5x4 " +
                           "--square-mm 20 --eye-to-hand --out " + dir_ + "/h.yaml 2>&1";
  FILE* pipe = popen(base.c_str(), "r");
  std::string output;
  char buf[512];
  while (std::fgets(buf, sizeof(buf), pipe) != nullptr) output += buf;
  EXPECT_NE(pclose(pipe), 0);
  EXPECT_NE(output.find("line 3: 6 numbers"), std::string::npos) << output;
  pipe = popen((std::string(STEREOHASH_EXE) + " calibrate-handeye --calib x 2>&1").c_str(), "r");
  output.clear();
  while (std::fgets(buf, sizeof(buf), pipe) != nullptr) output += buf;
  EXPECT_NE(pclose(pipe), 0);
  EXPECT_NE(output.find("required"), std::string::npos) << output;
}

}  // namespace
}  // namespace sh
