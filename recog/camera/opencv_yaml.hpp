// The subset of OpenCV's FileStorage YAML that calibration files use: a "%YAML:1.0" header,
// top-level "key: value" pairs, and "!!opencv-matrix" blocks (rows, cols, dt, data). Shared by
// the stereo calibration (calibration_yaml.hpp) and the table pose (table_yaml.hpp).
//
// Reading is strict and bounded: from the caller's buffer (need not be NUL-terminated), no
// allocation, the first problem reported with its line number. Unknown top-level keys and the
// indented blocks under them are skipped. Numbers are read with strtod (C locale).
#pragma once

#include <cstddef>

#include "recog/base/status.hpp"

namespace sh {

// Largest matrix read: a 14-coefficient distortion vector. Anything larger is refused before
// its numbers are stored.
inline constexpr int kMaxYamlMatrixEntries = 16;

struct YamlMatrix {
  bool present = false;
  int line = 0;
  int rows = 0;
  int cols = 0;
  int count = 0;
  double data[kMaxYamlMatrixEntries] = {};  // row-major
};

struct YamlInt {
  bool present = false;
  int line = 0;
  int value = 0;
};

// One top-level key the caller wants: exactly one of `integer` and `matrix` is set. `alias` is a
// second accepted spelling (OpenCV's older M1 for K1), or nullptr; `spelling` receives the one
// found (may be nullptr).
struct YamlKey {
  const char* name;
  const char* alias;
  YamlInt* integer;
  YamlMatrix* matrix;
  const char** spelling;
};

// Parses `text` (at most max_bytes) into the requested keys; `what` names the file kind in
// messages ("calibration file"). Duplicate keys, malformed matrices, non-finite numbers, NUL
// bytes and a missing header are errors; absent keys are not (check `present`).
Status ReadOpenCvYaml(const char* text, size_t length, size_t max_bytes, const char* what,
                      YamlKey* keys, size_t n_keys);

// Appends printf output to out[*used..capacity); false when it does not fit.
bool YamlAppend(char* out, size_t capacity, size_t* used, const char* fmt, ...)
    __attribute__((format(printf, 4, 5)));

// Appends "name: !!opencv-matrix" with rows, cols, dt d and the row-major data at 17 significant
// digits (parsing gives back the same doubles); false when it does not fit.
bool YamlAppendMatrix(char* out, size_t capacity, size_t* used, const char* name, int rows,
                      int cols, const double* data);

}  // namespace sh
