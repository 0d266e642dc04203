// The hand-eye file: written and read back, and each way a file can be wrong refused with the
// problem named.
#include <gtest/gtest.h>

#include <cstring>
#include <string>

#include "recog/camera/handeye_yaml.hpp"

namespace sh {
namespace {

HandEye Example(bool eye_in_hand) {
  HandEye h;
  h.eye_in_hand = eye_in_hand;
  h.robot_T_camera.R =
      Eigen::AngleAxisf(0.7f, Eigen::Vector3f(1, 2, 3).normalized()).toRotationMatrix();
  h.robot_T_camera.t_mm = Eigen::Vector3f(650.5f, -12.25f, 1480.0f);
  h.poses = 14;
  h.residual_rms_mm = 0.25;
  h.residual_max_mm = 0.5;
  h.residual_rms_deg = 0.03;
  h.residual_max_deg = 0.07;
  return h;
}

TEST(HandEyeYaml, RoundTrip) {
  for (bool in_hand : {false, true}) {
    char text[kMaxHandEyeYamlBytes];
    const Result<size_t> n = WriteHandEyeYaml(Example(in_hand), text, sizeof(text));
    ASSERT_TRUE(n.ok()) << n.status().message();
    const Result<HandEye> h = ParseHandEyeYaml(text, *n);
    ASSERT_TRUE(h.ok()) << h.status().message();
    EXPECT_EQ(h->eye_in_hand, in_hand);
    EXPECT_LT((h->robot_T_camera.R - Example(in_hand).robot_T_camera.R).norm(), 1e-6f);
    EXPECT_EQ(h->robot_T_camera.t_mm, Example(in_hand).robot_T_camera.t_mm);
    EXPECT_EQ(h->poses, 14);
    EXPECT_DOUBLE_EQ(h->residual_max_deg, 0.07);
  }
}

std::string Replace(std::string text, const std::string& from, const std::string& to) {
  const size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  if (at != std::string::npos) text.replace(at, from.size(), to);
  return text;
}

TEST(HandEyeYaml, BadFilesAreRefusedNamingTheProblem) {
  char buf[kMaxHandEyeYamlBytes];
  const Result<size_t> n = WriteHandEyeYaml(Example(false), buf, sizeof(buf));
  ASSERT_TRUE(n.ok());
  const std::string good(buf, *n);
  const struct {
    std::string text;
    const char* expected;
  } cases[] = {
      {Replace(good, "eye_in_hand: 0", "eye_in_hand: 3"), "eye_in_hand must be 0 or 1"},
      {Replace(good, "eye_in_hand: 0\n", ""), "missing key 'eye_in_hand'"},
      {Replace(good, "t_robot_camera", "t_camera"), "missing key 't_robot_camera'"},
      {Replace(good, "650.5", "6.5e7"), "not a hand-eye pose in millimetres"},
      {Replace(good, "rows: 3\n   cols: 3", "rows: 1\n   cols: 9"), "must be 3x3"},
      {"%YAML:1.0\n---\neye_in_hand: 0\nR_robot_camera: !!opencv-matrix\n   rows: 3\n   cols: 3\n"
       "   dt: d\n   data: [ 2, 0, 0, 0, 1, 0, 0, 0, 1 ]\nt_robot_camera: !!opencv-matrix\n"
       "   rows: 3\n   cols: 1\n   dt: d\n   data: [ 0, 0, 0 ]\n",
       "R_robot_camera"},
  };
  for (const auto& c : cases) {
    const Result<HandEye> h = ParseHandEyeYaml(c.text.data(), c.text.size());
    ASSERT_FALSE(h.ok()) << c.expected;
    SCOPED_TRACE(c.expected);
    EXPECT_NE(std::strstr(h.status().message(), c.expected), nullptr) << h.status().message();
  }
}

}  // namespace
}  // namespace sh
