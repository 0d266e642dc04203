// libFuzzer target: the table pose parser must return a Status for any input, never crash or
// read outside the input; whatever it accepts must survive a write/parse round trip.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>

#include "recog/camera/table_yaml.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  // Exactly sized heap copy so that ASan catches reads past the end (no terminating NUL).
  char* text = static_cast<char*>(std::malloc(size == 0 ? 1 : size));
  if (size > 0) std::memcpy(text, data, size);
  const sh::Result<sh::RigidTransform> parsed = sh::ParseTableYaml(text, size);
  std::free(text);
  if (!parsed.ok()) return 0;
  static char out[sh::kMaxTableYamlBytes];
  const sh::Result<size_t> written = sh::WriteTableYaml(*parsed, out, sizeof(out));
  if (!written.ok()) std::abort();  // an accepted pose must be writable
  const sh::Result<sh::RigidTransform> again = sh::ParseTableYaml(out, *written);
  if (!again.ok() || again->t_mm != parsed->t_mm || (again->R - parsed->R).norm() > 1e-5f) {
    std::abort();
  }
  return 0;
}
