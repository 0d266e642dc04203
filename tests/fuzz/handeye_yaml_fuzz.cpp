// libFuzzer target: the hand-eye file parser must return a Status for any input, never crash or
// read outside the input; whatever it accepts must survive a write/parse round trip.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>

#include "recog/camera/handeye_yaml.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  // Exactly sized heap copy so that ASan catches reads past the end (no terminating NUL).
  char* text = static_cast<char*>(std::malloc(size == 0 ? 1 : size));
  if (size > 0) std::memcpy(text, data, size);
  const sh::Result<sh::HandEye> parsed = sh::ParseHandEyeYaml(text, size);
  std::free(text);
  if (!parsed.ok()) return 0;
  static char out[sh::kMaxHandEyeYamlBytes];
  const sh::Result<size_t> written = sh::WriteHandEyeYaml(*parsed, out, sizeof(out));
  if (!written.ok()) std::abort();  // an accepted calibration must be writable
  const sh::Result<sh::HandEye> again = sh::ParseHandEyeYaml(out, *written);
  if (!again.ok() || again->eye_in_hand != parsed->eye_in_hand ||
      again->robot_T_camera.t_mm != parsed->robot_T_camera.t_mm ||
      (again->robot_T_camera.R - parsed->robot_T_camera.R).norm() > 1e-5f) {
    std::abort();
  }
  return 0;
}
