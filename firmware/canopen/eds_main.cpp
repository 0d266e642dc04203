// stereohash-eds: writes the sensor's EDS (CiA 306) to a file or stdout. The build runs it to
// produce the stereohash.eds that is installed beside the firmware.
#include <cstdio>
#include <cstring>

#include "firmware/canopen/eds_writer.hpp"

int main(int argc, char** argv) {
  if (argc > 2 || (argc == 2 && (!std::strcmp(argv[1], "--help") || !std::strcmp(argv[1], "-h")))) {
    std::printf(
        "usage: stereohash-eds [FILE]   write the EDS of the sensor (stdout without FILE)\n");
    return argc > 2 ? 2 : 0;
  }
  std::FILE* out = stdout;
  if (argc == 2) {
    out = std::fopen(argv[1], "w");
    if (out == nullptr) {
      std::fprintf(stderr, "stereohash-eds: cannot write %s\n", argv[1]);
      return 1;
    }
  }
  const sh::Status s = sh::canopen::WriteEds(out);
  const bool closed = out == stdout || std::fclose(out) == 0;
  if (!s.ok() || !closed) {
    std::fprintf(stderr, "stereohash-eds: %s\n", s.ok() ? "write error" : s.message());
    return 1;
  }
  return 0;
}
