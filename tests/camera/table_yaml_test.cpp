#include "recog/camera/table_yaml.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <string>

namespace sh {
namespace {

// The table.yaml of a recorded scene set, as written by the independent renderer: 12 digits,
// data on one line.
const char kRecorded[] =
    "%YAML:1.0\n"
    "---\n"
    "R_table: !!opencv-matrix\n"
    "   rows: 3\n"
    "   cols: 3\n"
    "   dt: d\n"
    "   data: [ 0.986393923832, -0.164398987305, 0, -0.102274478266, -0.613646869597, "
    "-0.782928764658, 0.128712696042, 0.772276176252, -0.622111364203 ]\n"
    "t_table: !!opencv-matrix\n"
    "   rows: 3\n"
    "   cols: 1\n"
    "   dt: d\n"
    "   data: [ 4.93196961916, 18.4094060879, 442.986195545 ]\n";

Result<RigidTransform> Parse(const std::string& text) {
  return ParseTableYaml(text.data(), text.size());
}

std::string Replace(std::string text, const std::string& from, const std::string& to) {
  const size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  if (at != std::string::npos) text.replace(at, from.size(), to);
  return text;
}

TEST(TableYaml, ReadsTheRecordedFormat) {
  const Result<RigidTransform> pose = Parse(kRecorded);
  ASSERT_TRUE(pose.ok()) << pose.status().message();
  EXPECT_NEAR(pose->R(0, 0), 0.986393923832f, 1e-6f);
  EXPECT_NEAR(pose->R(2, 1), 0.772276176252f, 1e-6f);
  EXPECT_NEAR(pose->t_mm.z(), 442.986195545f, 1e-3f);
  // An exact rotation: R^T R = I, det +1.
  EXPECT_LT((pose->R.transpose() * pose->R - Eigen::Matrix3f::Identity()).norm(), 1e-6f);
  EXPECT_NEAR(pose->R.determinant(), 1.0f, 1e-6f);
  // The table origin lies in front of the camera and the table normal faces it.
  EXPECT_GT(pose->t_mm.z(), 0.0f);
  EXPECT_LT(pose->R.col(2).dot(pose->t_mm), 0.0f);
}

TEST(TableYaml, RoundTrip) {
  RigidTransform pose;
  pose.R = (Eigen::AngleAxisf(2.4f, Eigen::Vector3f::UnitX()) *
            Eigen::AngleAxisf(0.3f, Eigen::Vector3f::UnitZ()))
               .toRotationMatrix();
  pose.t_mm = Eigen::Vector3f(12.5f, -30.25f, 512.0f);
  char buffer[2048];
  const Result<size_t> n = WriteTableYaml(pose, buffer, sizeof(buffer));
  ASSERT_TRUE(n.ok()) << n.status().message();
  const Result<RigidTransform> back = ParseTableYaml(buffer, *n);
  ASSERT_TRUE(back.ok()) << back.status().message();
  EXPECT_LT((back->R - pose.R).norm(), 1e-6f);
  EXPECT_EQ(back->t_mm, pose.t_mm);
}

TEST(TableYaml, WriterRefusesSmallBufferAndBadPose) {
  RigidTransform pose;
  pose.R = Eigen::AngleAxisf(3.0f, Eigen::Vector3f::UnitX()).toRotationMatrix();
  pose.t_mm = Eigen::Vector3f(0, 0, 500);
  char small[40];
  const Result<size_t> n = WriteTableYaml(pose, small, sizeof(small));
  EXPECT_EQ(n.status().code(), StatusCode::kResourceExhausted);
  EXPECT_STREQ(small, "");
  RigidTransform flipped = pose;
  flipped.R = Eigen::Matrix3f::Identity();  // z away from the camera
  char buffer[2048];
  EXPECT_FALSE(WriteTableYaml(flipped, buffer, sizeof(buffer)).ok());
}

TEST(TableYaml, ErrorsNameTheProblem) {
  const std::string good = kRecorded;
  struct Case {
    const char* what;
    std::string text;
    const char* message;
  };
  const Case cases[] = {
      {"empty", "", "empty"},
      {"not yaml", "R_table: 1\n", "%YAML"},
      {"no t", good.substr(0, good.find("t_table")), "missing key 't_table'"},
      {"no R", Replace(good, "R_table:", "Q_table:"), "missing key 'R_table'"},
      {"reflection", Replace(good, "0.986393923832", "-0.986393923832"), "not a rotation"},
      {"scaled", Replace(good, "0.986393923832", "0.996393923832"), "not a rotation"},
      {"nan", Replace(good, "442.986195545", "nan"), "non-finite"},
      {"far", Replace(good, "442.986195545", "4.4e9"), "more than"},
      {"t 2x1",
       Replace(Replace(good, "rows: 3\n   cols: 1", "rows: 2\n   cols: 1"), "18.4094060879, ", ""),
       "t_table must be 3x1"},
      {"R 1x9", Replace(good, "rows: 3\n   cols: 3", "rows: 1\n   cols: 9"), "R_table must be 3x3"},
      {"duplicate", good + "t_table: !!opencv-matrix\n", "duplicates"},
      {"short data", Replace(good, ", 442.986195545", ""), "data has 2 numbers"},
      {"nul", std::string("%YAML:1.0\n\0", 11), "NUL"},
      {"upside down",
       Replace(Replace(good, "-0.782928764658", "0.782928764658"), "-0.622111364203",
               "0.622111364203"),
       "not a rotation"},
  };
  for (const Case& c : cases) {
    const Result<RigidTransform> r = Parse(c.text);
    ASSERT_FALSE(r.ok()) << c.what;
    EXPECT_NE(std::string(r.status().message()).find(c.message), std::string::npos)
        << c.what << ": " << r.status().message();
  }
}

TEST(TableYaml, RefusesATableSeenFromBelow) {
  // A valid rotation whose z axis points away from the camera: the frame is upside down.
  RigidTransform pose;
  pose.R = Eigen::AngleAxisf(0.3f, Eigen::Vector3f::UnitX()).toRotationMatrix();
  pose.t_mm = Eigen::Vector3f(0, 0, 500);
  char buffer[2048];
  // Write a valid file first, then flip the pose's z and y axes' signs in the text.
  RigidTransform up = pose;
  up.R.col(1) = -up.R.col(1);
  up.R.col(2) = -up.R.col(2);
  const Result<size_t> n = WriteTableYaml(up, buffer, sizeof(buffer));
  ASSERT_TRUE(n.ok()) << n.status().message();
  EXPECT_TRUE(ParseTableYaml(buffer, *n).ok());
  const Result<size_t> m = WriteTableYaml(pose, buffer, sizeof(buffer));
  ASSERT_FALSE(m.ok());
  EXPECT_NE(std::string(m.status().message()).find("z axis points away"), std::string::npos);
}

}  // namespace
}  // namespace sh
