#include "recog/camera/calibration_yaml.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cstring>
#include <random>
#include <string>

#include "recog/camera/calibration_check.hpp"
#include "tests/support/calibrations.hpp"

namespace sh {
namespace {

// 640 x 480 rigs: the cases below edit "image_width: 640" and "image_height: 480".
StereoCalibration RandomCalibration(std::mt19937& rng) {
  return testing::RandomCalibration(rng, 640, 480);
}

std::string Write(const StereoCalibration& c) {
  char buf[8192];
  const Result<size_t> n = WriteCalibrationYaml(c, buf, sizeof(buf));
  EXPECT_TRUE(n.ok()) << n.status().message();
  return n.ok() ? std::string(buf, *n) : std::string();
}

Result<StereoCalibration> Parse(const std::string& text) {
  return ParseCalibrationYaml(text.data(), text.size());
}

// Replaces the first occurrence of `from`; the test fails if it is absent.
std::string Replace(std::string text, const std::string& from, const std::string& to) {
  const size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  if (at != std::string::npos) text.replace(at, from.size(), to);
  return text;
}

void ExpectSameCamera(const CameraIntrinsics& a, const CameraIntrinsics& b) {
  EXPECT_EQ(a.width, b.width);
  EXPECT_EQ(a.height, b.height);
  EXPECT_EQ(a.fx, b.fx);
  EXPECT_EQ(a.fy, b.fy);
  EXPECT_EQ(a.cx, b.cx);
  EXPECT_EQ(a.cy, b.cy);
  EXPECT_EQ(a.k1, b.k1);
  EXPECT_EQ(a.k2, b.k2);
  EXPECT_EQ(a.p1, b.p1);
  EXPECT_EQ(a.p2, b.p2);
  EXPECT_EQ(a.k3, b.k3);
}

TEST(CalibrationYaml, RoundTripIsExact) {
  std::mt19937 rng(7);
  for (int i = 0; i < 50; ++i) {
    const StereoCalibration c = RandomCalibration(rng);
    const Result<StereoCalibration> back = Parse(Write(c));
    ASSERT_TRUE(back.ok()) << back.status().message();
    ExpectSameCamera(c.left, back->left);
    ExpectSameCamera(c.right, back->right);
    EXPECT_EQ(c.right_t_left_mm, back->right_t_left_mm);
    // R passes through NearestRotation: equal up to rounding.
    EXPECT_LT((c.right_R_left - back->right_R_left).cwiseAbs().maxCoeff(), 1e-14);
  }
}

// The layout OpenCV's stereo_calib sample and FileStorage produce: M1/M2 names, data continued
// on following lines, extra keys with nested blocks, comments and CRLF line ends.
const char kOpenCvStyle[] =
    "%YAML:1.0\r\n"
    "---\r\n"
    "calibration_time: \"Mon [sic] 1 Jan\"\r\n"
    "image_width: 640\r\n"
    "image_height: 480\r\n"
    "# intrinsics\r\n"
    "M1: !!opencv-matrix\r\n"
    "   rows: 3\r\n"
    "   cols: 3\r\n"
    "   dt: d\r\n"
    "   data: [ 5.3591573396163199e+02, 0., 3.4228315473308373e+02, 0.,\r\n"
    "       5.3591573396163199e+02, 2.3557082909788173e+02, 0., 0., 1. ]\r\n"
    "D1: !!opencv-matrix\r\n"
    "   rows: 5\r\n"
    "   cols: 1\r\n"
    "   dt: d\r\n"
    "   data: [ -2.6637260909660682e-01, -3.8588898922304653e-02,\r\n"
    "       1.7831947042852964e-03, -2.8122100441115472e-04,\r\n"
    "       2.3839153080878486e-01 ]\r\n"
    "M2: !!opencv-matrix\r\n"
    "   rows: 3\r\n"
    "   cols: 3\r\n"
    "   dt: f\r\n"
    "   data: [ 540., 0., 320., 0., 541., 241., 0., 0., 1. ]\r\n"
    "D2: !!opencv-matrix\r\n"
    "   rows: 1\r\n"
    "   cols: 8\r\n"
    "   dt: d\r\n"
    "   data: [ -0.25, 0.1, 0., 0., 0., 0., 0., 0. ]\r\n"
    "per_view_errors: [ 0.1, 0.2,\r\n"
    "   0.3 ]\r\n"
    "nested:\r\n"
    "   a: 1\r\n"
    "   b: [ 1, 2 ]\r\n"
    "R: !!opencv-matrix\r\n"
    "   rows: 3\r\n"
    "   cols: 3\r\n"
    "   dt: d\r\n"
    "   data: [ 1., 0., 0., 0., 1., 0., 0., 0., 1. ]\r\n"
    "T: !!opencv-matrix\r\n"
    "   rows: 1\r\n"
    "   cols: 3\r\n"
    "   dt: d\r\n"
    "   data: [ -100.5, 0.25, 1e-1 ]   # millimetres\r\n"
    "E: !!opencv-matrix\r\n"
    "   rows: 3\r\n"
    "   cols: 3\r\n"
    "   dt: d\r\n"
    "   data: [ 0., 0., 0., 0., 0., 0., 0., 0., 0. ]\r\n";

TEST(CalibrationYaml, ReadsOpenCvLayout) {
  const Result<StereoCalibration> c = ParseCalibrationYaml(kOpenCvStyle, std::strlen(kOpenCvStyle));
  ASSERT_TRUE(c.ok()) << c.status().message();
  EXPECT_EQ(c->left.width, 640);
  EXPECT_EQ(c->right.height, 480);
  EXPECT_DOUBLE_EQ(c->left.fx, 5.3591573396163199e+02);
  EXPECT_DOUBLE_EQ(c->left.cy, 2.3557082909788173e+02);
  EXPECT_DOUBLE_EQ(c->left.k3, 2.3839153080878486e-01);
  EXPECT_DOUBLE_EQ(c->right.fy, 541.0);
  EXPECT_DOUBLE_EQ(c->right.k1, -0.25);
  EXPECT_DOUBLE_EQ(c->right.k3, 0.0);
  EXPECT_EQ(c->right_t_left_mm, Eigen::Vector3d(-100.5, 0.25, 0.1));
}

TEST(CalibrationYaml, FourCoefficientDistortionMeansZeroK3) {
  std::mt19937 rng(3);
  const std::string text =
      Replace(Write(RandomCalibration(rng)), "D1: !!opencv-matrix\n   rows: 1\n   cols: 5",
              "D1: !!opencv-matrix\n   rows: 1\n   cols: 4");
  // Drop the fifth number of D1.
  const size_t d1 = text.find("D1:");
  const size_t close = text.find(" ]", d1);
  const size_t last_comma = text.rfind(',', close);
  const std::string four = text.substr(0, last_comma) + text.substr(close);
  const Result<StereoCalibration> c = Parse(four);
  ASSERT_TRUE(c.ok()) << c.status().message();
  EXPECT_EQ(c->left.k3, 0.0);
}

struct BadCase {
  const char* name;
  std::string text;
  StatusCode code;
  const char* message_part;
};

TEST(CalibrationYaml, MalformedFilesGiveTheRightError) {
  std::mt19937 rng(11);
  StereoCalibration base = RandomCalibration(rng);
  base.right_R_left.setIdentity();  // so the R text below is predictable
  const std::string good = Write(base);
  ASSERT_TRUE(Parse(good).ok());
  // The writer puts four numbers on a line.
  const auto r_data = [](const char* first) {
    return std::string("data: [ ") + first + ", 0., 0., 0.,\n       1., 0., 0., 0.,\n       1. ]";
  };
  const std::string identity_data = r_data("1.");
  ASSERT_NE(good.find(identity_data), std::string::npos);

  std::string without_k1 = good;
  {
    const size_t a = without_k1.find("K1:");
    const size_t b = without_k1.find("D1:");
    without_k1.erase(a, b - a);
  }
  const BadCase cases[] = {
      {"empty", "", StatusCode::kInvalidArgument, "empty"},
      {"no header", good.substr(good.find('\n') + 1), StatusCode::kInvalidArgument, "%YAML"},
      {"garbage", "%YAML:1.0\n---\nhello world\n", StatusCode::kInvalidArgument, "line 3"},
      {"binary", std::string("%YAML:1.0\n\x01\x02\x00\x03", 14), StatusCode::kInvalidArgument,
       "NUL"},
      {"missing K1", without_k1, StatusCode::kInvalidArgument, "missing key 'K1'"},
      {"missing width", Replace(good, "image_width: 640\n", ""), StatusCode::kInvalidArgument,
       "missing key 'image_width'"},
      {"width not integer", Replace(good, "image_width: 640", "image_width: 6x0"),
       StatusCode::kInvalidArgument, "not an integer"},
      {"zero size", Replace(good, "image_height: 480", "image_height: 0"),
       StatusCode::kInvalidArgument, "must be positive"},
      {"oversize", Replace(good, "image_width: 640", "image_width: 4096"), StatusCode::kOutOfRange,
       "exceeds"},
      {"K wrong size",
       Replace(good, "K1: !!opencv-matrix\n   rows: 3\n   cols: 3",
               "K1: !!opencv-matrix\n   rows: 1\n   cols: 9"),
       StatusCode::kInvalidArgument, "K1 must be 3x3"},
      {"count mismatch",
       Replace(good, "R: !!opencv-matrix\n   rows: 3", "R: !!opencv-matrix\n   rows: 2"),
       StatusCode::kInvalidArgument, "data has 9 numbers but rows x cols = 2 x 3"},
      {"nan", Replace(good, identity_data, r_data(".nan")), StatusCode::kInvalidArgument,
       "non-finite"},
      {"overflow", Replace(good, identity_data, r_data("1e999")), StatusCode::kInvalidArgument,
       "non-finite"},
      {"not a number", Replace(good, identity_data, r_data("1.0.0")), StatusCode::kInvalidArgument,
       "not a number"},
      {"reflection", Replace(good, identity_data, r_data("-1.")), StatusCode::kInvalidArgument,
       "det"},
      {"not orthonormal", Replace(good, identity_data, r_data("1.1")), StatusCode::kInvalidArgument,
       "not a rotation"},
      {"negative focal", Replace(good, "data: [ ", "data: [ -"), StatusCode::kInvalidArgument,
       "focal length"},
      {"unclosed data", good.substr(0, good.rfind(" ]")), StatusCode::kInvalidArgument,
       "not closed"},
      {"bad dt", Replace(good, "dt: d", "dt: u"), StatusCode::kInvalidArgument, "dt 'u'"},
      {"not a matrix", Replace(good, "R: !!opencv-matrix", "R: 3"), StatusCode::kInvalidArgument,
       "R must be a '!!opencv-matrix'"},
      {"duplicate", Replace(good, "K2:", "M1:"), StatusCode::kInvalidArgument, "duplicates"},
      {"bad indentation", Replace(good, "image_height", "  image_height"),
       StatusCode::kInvalidArgument, "indentation"},
      {"unknown matrix field", Replace(good, "dt: d", "type: d"), StatusCode::kInvalidArgument,
       "unexpected matrix field 'type'"},
      {"zero baseline",
       Replace(good, "T: !!opencv-matrix\n   rows: 3\n   cols: 1\n   dt: d\n",
               "T: !!opencv-matrix\n   rows: 3\n   cols: 1\n   dt: d\n"
               "   data: [ 0., 0., 0. ]\nT_old: !!opencv-matrix\n   rows: 3\n"
               "   cols: 1\n   dt: d\n"),
       StatusCode::kInvalidArgument, "baseline"},
      {"oversized file", good + std::string(kMaxCalibrationYamlBytes, '#'), StatusCode::kOutOfRange,
       "bytes"},
  };
  for (const BadCase& c : cases) {
    const Result<StereoCalibration> r = Parse(c.text);
    ASSERT_FALSE(r.ok()) << c.name;
    EXPECT_EQ(r.status().code(), c.code) << c.name << ": " << r.status().message();
    EXPECT_NE(std::strstr(r.status().message(), c.message_part), nullptr)
        << c.name << ": '" << r.status().message() << "' lacks '" << c.message_part << "'";
  }
}

TEST(CalibrationYaml, DistortionModelsBeyondK3AreRefusedUnlessZero) {
  std::mt19937 rng(5);
  const std::string good = Write(RandomCalibration(rng));
  const size_t d1 = good.find("D1:");
  const size_t close = good.find(" ]", d1);
  const std::string eight_zero = Replace(
      good.substr(0, close) + ", 0., 0., 0." + good.substr(close),
      "D1: !!opencv-matrix\n   rows: 1\n   cols: 5", "D1: !!opencv-matrix\n   rows: 1\n   cols: 8");
  EXPECT_TRUE(Parse(eight_zero).ok()) << Parse(eight_zero).status().message();
  const std::string eight_rational = Replace(eight_zero, ", 0., 0., 0. ]", ", 0.01, 0., 0. ]");
  const Result<StereoCalibration> r = Parse(eight_rational);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(std::strstr(r.status().message(), "rational"), nullptr) << r.status().message();
  EXPECT_NE(std::strstr(r.status().message(), "D1"), nullptr) << r.status().message();

  const std::string six = Replace(good.substr(0, close) + ", 0." + good.substr(close),
                                  "D1: !!opencv-matrix\n   rows: 1\n   cols: 5",
                                  "D1: !!opencv-matrix\n   rows: 1\n   cols: 6");
  const Result<StereoCalibration> r6 = Parse(six);
  ASSERT_FALSE(r6.ok());
  EXPECT_NE(std::strstr(r6.status().message(), "D1 has 6 coefficients"), nullptr)
      << r6.status().message();
}

TEST(CalibrationYaml, EveryTruncationIsAnErrorNotACrash) {
  std::mt19937 rng(13);
  const std::string good = Write(RandomCalibration(rng));
  const size_t last_bracket = good.rfind(']');
  for (size_t n = 0; n <= last_bracket; ++n) {
    EXPECT_FALSE(ParseCalibrationYaml(good.data(), n).ok()) << "prefix of " << n << " bytes";
  }
  EXPECT_TRUE(ParseCalibrationYaml(good.data(), last_bracket + 1).ok());
}

TEST(CalibrationYaml, WriterRefusesSmallBufferAndInvalidCalibration) {
  std::mt19937 rng(17);
  StereoCalibration c = RandomCalibration(rng);
  char small[200];
  const Result<size_t> r = WriteCalibrationYaml(c, small, sizeof(small));
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.status().code(), StatusCode::kResourceExhausted);
  EXPECT_EQ(small[0], '\0');

  char buf[8192];
  c.left.fx = -1.0;
  EXPECT_FALSE(WriteCalibrationYaml(c, buf, sizeof(buf)).ok());
  c = RandomCalibration(rng);
  c.right.width = 320;
  EXPECT_FALSE(WriteCalibrationYaml(c, buf, sizeof(buf)).ok());
}

}  // namespace
}  // namespace sh
