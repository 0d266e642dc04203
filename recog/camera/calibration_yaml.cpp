#include "recog/camera/calibration_yaml.hpp"

#include "recog/camera/calibration_check.hpp"
#include "recog/camera/opencv_yaml.hpp"

namespace sh {
namespace {

Status ToIntrinsics(const YamlMatrix& K, const char* k_name, const YamlMatrix& D,
                    const char* d_name, int width, int height, CameraIntrinsics* cam) {
  if (K.rows != 3 || K.cols != 3) {
    return Status::Error(StatusCode::kInvalidArgument, "%s must be 3x3, got %dx%d", k_name, K.rows,
                         K.cols);
  }
  const double* k = K.data;
  if (k[3] != 0.0 || k[6] != 0.0 || k[7] != 0.0 || k[8] != 1.0) {
    return Status::Error(StatusCode::kInvalidArgument,
                         "%s is not a camera matrix: expected [fx 0 cx; 0 fy cy; 0 0 1]", k_name);
  }
  if (std::fabs(k[1]) > 1e-9 * std::fabs(k[0])) {
    return Status::Error(StatusCode::kInvalidArgument, "%s has skew %g; the camera model has none",
                         k_name, k[1]);
  }
  if (D.rows != 1 && D.cols != 1) {
    return Status::Error(StatusCode::kInvalidArgument, "%s must be a vector, got %dx%d", d_name,
                         D.rows, D.cols);
  }
  const int n = D.count;
  if (n == 8 || n == 12 || n == 14) {
    for (int i = 5; i < n; ++i) {
      if (D.data[i] != 0.0) {
        return Status::Error(StatusCode::kInvalidArgument,
                             "%s has %d coefficients with non-zero %s: the rational, thin-prism "
                             "and tilted models are not supported (k1 k2 p1 p2 [k3] only)",
                             d_name, n,
                             i < 8    ? "k4..k6"
                             : i < 12 ? "s1..s4"
                                      : "tau");
      }
    }
  } else if (n != 4 && n != 5) {
    return Status::Error(StatusCode::kInvalidArgument,
                         "%s has %d coefficients; expected 4 or 5 (k1 k2 p1 p2 [k3])", d_name, n);
  }
  cam->width = width;
  cam->height = height;
  cam->fx = k[0];
  cam->cx = k[2];
  cam->fy = k[4];
  cam->cy = k[5];
  cam->k1 = D.data[0];
  cam->k2 = D.data[1];
  cam->p1 = D.data[2];
  cam->p2 = D.data[3];
  cam->k3 = n >= 5 ? D.data[4] : 0.0;
  return Status::Ok();
}

}  // namespace

Result<StereoCalibration> ParseCalibrationYaml(const char* text, size_t length) {
  YamlInt width, height;
  // K1, D1, K2, D2, R, T; OpenCV's older stereo_calib writes M1 / M2 for the camera matrices.
  YamlMatrix K1, D1, K2, D2, R, T;
  const char* k1_name = "K1";
  const char* k2_name = "K2";
  YamlKey keys[] = {{"image_width", nullptr, &width, nullptr, nullptr},
                    {"image_height", nullptr, &height, nullptr, nullptr},
                    {"K1", "M1", nullptr, &K1, &k1_name},
                    {"D1", nullptr, nullptr, &D1, nullptr},
                    {"K2", "M2", nullptr, &K2, &k2_name},
                    {"D2", nullptr, nullptr, &D2, nullptr},
                    {"R", nullptr, nullptr, &R, nullptr},
                    {"T", nullptr, nullptr, &T, nullptr}};
  SH_RETURN_IF_ERROR(ReadOpenCvYaml(text, length, kMaxCalibrationYamlBytes, "calibration file",
                                    keys, sizeof(keys) / sizeof(keys[0])));
  for (const YamlKey& k : keys) {
    const bool present = k.integer != nullptr ? k.integer->present : k.matrix->present;
    if (!present) {
      if (k.alias != nullptr) {
        return Status::Error(StatusCode::kInvalidArgument, "missing key '%s' (or '%s')", k.name,
                             k.alias);
      }
      return Status::Error(StatusCode::kInvalidArgument, "missing key '%s'", k.name);
    }
  }

  StereoCalibration calib;
  SH_RETURN_IF_ERROR(ToIntrinsics(K1, k1_name, D1, "D1", width.value, height.value, &calib.left));
  SH_RETURN_IF_ERROR(ToIntrinsics(K2, k2_name, D2, "D2", width.value, height.value, &calib.right));
  if (R.rows != 3 || R.cols != 3) {
    return Status::Error(StatusCode::kInvalidArgument, "R must be 3x3, got %dx%d", R.rows, R.cols);
  }
  if (T.count != 3 || (T.rows != 1 && T.cols != 1)) {
    return Status::Error(StatusCode::kInvalidArgument, "T must be 3x1 or 1x3, got %dx%d", T.rows,
                         T.cols);
  }
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) calib.right_R_left(r, c) = R.data[r * 3 + c];  // row-major data
    calib.right_t_left_mm(r) = T.data[r];
  }
  SH_RETURN_IF_ERROR(ValidateStereoCalibration(calib, kSensorBounds));
  calib.right_R_left = NearestRotation(calib.right_R_left);
  return calib;
}

Result<size_t> WriteCalibrationYaml(const StereoCalibration& calib, char* out, size_t capacity) {
  SH_RETURN_IF_ERROR(ValidateStereoCalibration(calib, kSensorBounds));
  if (calib.left.width != calib.right.width || calib.left.height != calib.right.height) {
    return Status::Error(StatusCode::kInvalidArgument,
                         "left image %dx%d and right image %dx%d differ; the file holds one size",
                         calib.left.width, calib.left.height, calib.right.width,
                         calib.right.height);
  }
  if (out == nullptr || capacity == 0) {
    return Status::Error(StatusCode::kInvalidArgument, "no output buffer");
  }
  size_t used = 0;
  bool fits =
      YamlAppend(out, capacity, &used, "%%YAML:1.0\n---\nimage_width: %d\nimage_height: %d\n",
                 calib.left.width, calib.left.height);
  const CameraIntrinsics* cams[2] = {&calib.left, &calib.right};
  for (int i = 0; i < 2 && fits; ++i) {
    const CameraIntrinsics& c = *cams[i];
    const double K[9] = {c.fx, 0.0, c.cx, 0.0, c.fy, c.cy, 0.0, 0.0, 1.0};
    const double D[5] = {c.k1, c.k2, c.p1, c.p2, c.k3};
    fits = YamlAppendMatrix(out, capacity, &used, i == 0 ? "K1" : "K2", 3, 3, K) &&
           YamlAppendMatrix(out, capacity, &used, i == 0 ? "D1" : "D2", 1, 5, D);
  }
  double R[9];
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) R[r * 3 + c] = calib.right_R_left(r, c);
  }
  const double T[3] = {calib.right_t_left_mm.x(), calib.right_t_left_mm.y(),
                       calib.right_t_left_mm.z()};
  fits = fits && YamlAppendMatrix(out, capacity, &used, "R", 3, 3, R) &&
         YamlAppendMatrix(out, capacity, &used, "T", 3, 1, T);
  if (!fits) {
    out[0] = '\0';
    return Status::Error(StatusCode::kResourceExhausted,
                         "calibration YAML does not fit the %zu-byte output buffer", capacity);
  }
  return used;
}

}  // namespace sh
