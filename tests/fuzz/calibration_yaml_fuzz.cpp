// libFuzzer target: the calibration parser must return a Status for any input, never crash or
// read outside the input; whatever it accepts must survive a write/parse round trip unchanged.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>

#include "recog/camera/calibration_yaml.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  // Copy into an exactly sized heap block so that ASan catches any read past the end (the
  // parser never relies on a terminating NUL).
  char* text = static_cast<char*>(std::malloc(size == 0 ? 1 : size));
  if (size > 0) std::memcpy(text, data, size);
  const sh::Result<sh::StereoCalibration> parsed = sh::ParseCalibrationYaml(text, size);
  std::free(text);
  if (!parsed.ok()) return 0;

  static char out[sh::kMaxCalibrationYamlBytes];
  const sh::Result<size_t> written = sh::WriteCalibrationYaml(*parsed, out, sizeof(out));
  if (!written.ok()) std::abort();  // an accepted calibration must be writable
  const sh::Result<sh::StereoCalibration> again = sh::ParseCalibrationYaml(out, *written);
  if (!again.ok()) std::abort();
  const sh::CameraIntrinsics& a = parsed->left;
  const sh::CameraIntrinsics& b = again->left;
  if (a.fx != b.fx || a.fy != b.fy || a.cx != b.cx || a.k1 != b.k1 || a.k3 != b.k3 ||
      parsed->right_t_left_mm != again->right_t_left_mm) {
    std::abort();
  }
  return 0;
}
