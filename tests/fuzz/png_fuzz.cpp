// libFuzzer target: the PNG decoder must return a Status for any input, never crash or read
// outside the input or the output buffer.
#include <cstddef>
#include <cstdint>
#include <vector>

#include "hal/sim/image_files.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  // A small output buffer also exercises the capacity check; most fuzzed headers are small.
  static std::vector<uint8_t> pixels(size_t{256} * 256 * 3);
  const sh::hal::PixelFormat format =
      size > 0 && (data[size - 1] & 1) ? sh::hal::PixelFormat::kRgb8 : sh::hal::PixelFormat::kGray8;
  (void)sh::hal::DecodePng(data, size, format, pixels.data(), pixels.size());
  return 0;
}
