#include "recog/camera/calibration_yaml.hpp"

#include <strings.h>

#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <cstdlib>
#include <cstring>

#include "recog/camera/calibration_check.hpp"

namespace sh {
namespace {

// Largest matrix read: a 14-coefficient distortion vector. Anything larger is refused before
// its numbers are stored.
constexpr int kMaxMatrixEntries = 16;
constexpr int kMaxMatrixDim = 16;
// Longest number token; OpenCV writes at most ~24 characters ("-2.6637260909660682e-01").
constexpr size_t kMaxTokenChars = 48;

struct ParsedMatrix {
  bool present = false;
  int line = 0;
  int rows = 0;
  int cols = 0;
  int count = 0;
  double data[kMaxMatrixEntries] = {};
};

// The keys we read; everything else is skipped.
enum MatrixSlot { kK1, kD1, kK2, kD2, kR, kT, kMatrixSlots };

struct ParsedFile {
  bool has_width = false;
  bool has_height = false;
  int width = 0;
  int height = 0;
  ParsedMatrix matrices[kMatrixSlots];
  const char* names[kMatrixSlots] = {};  // spelling found in the file (K1 or M1)
};

bool IsInlineSpace(char c) { return c == ' ' || c == '\t' || c == '\r'; }
bool IsKeyChar(char c) {
  return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_';
}
bool IsDigit(char c) { return c >= '0' && c <= '9'; }

class Reader {
 public:
  Reader(const char* text, size_t length) : p_(text), end_(text + length) {}

  int line() const { return line_; }
  bool AtEnd() const { return p_ == end_; }
  char Peek() const { return p_ == end_ ? '\0' : *p_; }

  void SkipInlineSpace() {
    while (p_ != end_ && IsInlineSpace(*p_)) ++p_;
  }

  // Skips spaces, newlines and comments (inside a flow sequence, which may span lines).
  void SkipSpaceAcrossLines() {
    while (p_ != end_) {
      if (IsInlineSpace(*p_)) {
        ++p_;
      } else if (*p_ == '\n') {
        ++p_;
        ++line_;
      } else if (*p_ == '#') {
        while (p_ != end_ && *p_ != '\n') ++p_;
      } else {
        break;
      }
    }
  }

  // Skips blank and comment-only lines; leaves the cursor at the start of the next line with
  // content (or at the end).
  void SkipBlankLines() {
    while (p_ != end_) {
      const char* q = p_;
      while (q != end_ && IsInlineSpace(*q)) ++q;
      if (q == end_) {
        p_ = end_;
        return;
      }
      if (*q == '#') {
        while (q != end_ && *q != '\n') ++q;
      }
      if (q != end_ && *q == '\n') {
        p_ = q + 1;
        ++line_;
        continue;
      }
      if (q == end_) {
        p_ = end_;
        return;
      }
      return;
    }
  }

  // Indentation (spaces and tabs) of the current line; the cursor must be at a line start.
  int Indent() const {
    int n = 0;
    const char* q = p_;
    while (q != end_ && (*q == ' ' || *q == '\t')) {
      ++q;
      ++n;
    }
    return n;
  }

  // Reads a key at the cursor (after indentation) up to ':'.
  Status ReadKey(char* key, size_t capacity) {
    SkipInlineSpace();
    size_t n = 0;
    while (p_ != end_ && IsKeyChar(*p_)) {
      if (n + 1 >= capacity) {
        return Status::Error(StatusCode::kInvalidArgument, "line %d: key longer than %zu chars",
                             line_, capacity - 1);
      }
      key[n++] = *p_++;
    }
    key[n] = '\0';
    SkipInlineSpace();
    if (n == 0 || Peek() != ':') {
      return Status::Error(StatusCode::kInvalidArgument, "line %d: expected 'key: value'", line_);
    }
    ++p_;
    SkipInlineSpace();
    return Status::Ok();
  }

  // Reads a plain token (no spaces, commas, brackets or comment marks) into a NUL-terminated
  // buffer. An empty token is allowed; callers decide whether that is an error.
  Status ReadToken(char* token, size_t capacity) {
    size_t n = 0;
    while (p_ != end_ && !IsInlineSpace(*p_) && *p_ != '\n' && *p_ != ',' && *p_ != '[' &&
           *p_ != ']' && *p_ != '#' && *p_ != '{' && *p_ != '}') {
      if (n + 1 >= capacity) {
        return Status::Error(StatusCode::kInvalidArgument, "line %d: value longer than %zu chars",
                             line_, capacity - 1);
      }
      token[n++] = *p_++;
    }
    token[n] = '\0';
    return Status::Ok();
  }

  // Requires the rest of the line to be empty or a comment and moves to the next line.
  Status FinishLine() {
    SkipInlineSpace();
    if (p_ != end_ && *p_ == '#') {
      while (p_ != end_ && *p_ != '\n') ++p_;
    }
    if (p_ == end_) return Status::Ok();
    if (*p_ != '\n') {
      return Status::Error(StatusCode::kInvalidArgument, "line %d: unexpected '%c' after value",
                           line_, *p_);
    }
    ++p_;
    ++line_;
    return Status::Ok();
  }

  bool Consume(char c) {
    if (Peek() != c) return false;
    ++p_;
    return true;
  }

  // Skips the rest of a line, following flow collections ([...], {...}) and quoted strings
  // across line ends.
  Status SkipValue() {
    int depth = 0;
    char quote = '\0';
    while (p_ != end_) {
      const char c = *p_;
      if (quote != '\0') {
        if (c == quote) quote = '\0';
        if (c == '\n') ++line_;
        ++p_;
        continue;
      }
      if (c == '"' || c == '\'') {
        quote = c;
      } else if (c == '[' || c == '{') {
        ++depth;
      } else if (c == ']' || c == '}') {
        if (depth == 0) {
          return Status::Error(StatusCode::kInvalidArgument, "line %d: unbalanced '%c'", line_, c);
        }
        --depth;
      } else if (c == '#' && depth == 0) {
        while (p_ != end_ && *p_ != '\n') ++p_;
        continue;
      } else if (c == '\n') {
        ++line_;
        ++p_;
        if (depth == 0) return Status::Ok();
        continue;
      }
      ++p_;
    }
    if (quote != '\0' || depth != 0) {
      return Status::Error(StatusCode::kInvalidArgument,
                           "line %d: unterminated quoted string or flow collection at end of file",
                           line_);
    }
    return Status::Ok();
  }

  // True when the text at the cursor starts with `prefix`.
  bool StartsWith(const char* prefix) const {
    const size_t n = std::strlen(prefix);
    return static_cast<size_t>(end_ - p_) >= n && std::memcmp(p_, prefix, n) == 0;
  }

 private:
  const char* p_;
  const char* end_;
  int line_ = 1;
};

bool IsNonFiniteSpelling(const char* token) {
  const char* t = token;
  if (*t == '+' || *t == '-') ++t;
  if (*t == '.') ++t;
  return strncasecmp(t, "nan", 3) == 0 || strncasecmp(t, "inf", 3) == 0;
}

// Strict decimal number: [+-] digits [. digits] [e [+-] digits], at least one mantissa digit.
bool IsDecimalNumber(const char* t) {
  if (*t == '+' || *t == '-') ++t;
  int digits = 0;
  while (IsDigit(*t)) ++t, ++digits;
  if (*t == '.') {
    ++t;
    while (IsDigit(*t)) ++t, ++digits;
  }
  if (digits == 0) return false;
  if (*t == 'e' || *t == 'E') {
    ++t;
    if (*t == '+' || *t == '-') ++t;
    if (!IsDigit(*t)) return false;
    while (IsDigit(*t)) ++t;
  }
  return *t == '\0';
}

Status ParseDouble(const char* token, const char* what, int line, double* value) {
  if (IsNonFiniteSpelling(token)) {
    return Status::Error(StatusCode::kInvalidArgument, "line %d: %s: non-finite number '%s'", line,
                         what, token);
  }
  if (!IsDecimalNumber(token)) {
    return Status::Error(StatusCode::kInvalidArgument, "line %d: %s: '%s' is not a number", line,
                         what, token);
  }
  *value = std::strtod(token, nullptr);
  if (!std::isfinite(*value)) {
    return Status::Error(StatusCode::kInvalidArgument,
                         "line %d: %s: number '%s' overflows (non-finite)", line, what, token);
  }
  return Status::Ok();
}

// Integers up to 9 digits (image sizes, matrix dimensions); no overflow possible.
Status ParseInt(const char* token, const char* what, int line, int* value) {
  const char* t = token;
  const bool negative = *t == '-';
  if (*t == '+' || *t == '-') ++t;
  int digits = 0;
  long v = 0;
  while (IsDigit(*t)) {
    if (++digits > 9) {
      return Status::Error(StatusCode::kOutOfRange, "line %d: %s: '%s' is out of range", line, what,
                           token);
    }
    v = v * 10 + (*t++ - '0');
  }
  if (digits == 0 || *t != '\0') {
    return Status::Error(StatusCode::kInvalidArgument, "line %d: %s: '%s' is not an integer", line,
                         what, token);
  }
  *value = static_cast<int>(negative ? -v : v);
  return Status::Ok();
}

Status ParseMatrixData(Reader& in, const char* name, ParsedMatrix* m) {
  in.SkipInlineSpace();
  if (!in.Consume('[')) {
    return Status::Error(StatusCode::kInvalidArgument, "line %d: %s: data must start with '['",
                         in.line(), name);
  }
  m->count = 0;
  in.SkipSpaceAcrossLines();
  if (in.Consume(']')) return in.FinishLine();
  while (true) {
    in.SkipSpaceAcrossLines();
    if (in.AtEnd()) {
      return Status::Error(StatusCode::kInvalidArgument, "line %d: %s: data list not closed by ']'",
                           in.line(), name);
    }
    char token[kMaxTokenChars];
    SH_RETURN_IF_ERROR(in.ReadToken(token, sizeof(token)));
    if (token[0] == '\0') {
      return Status::Error(StatusCode::kInvalidArgument, "line %d: %s: expected a number, got '%c'",
                           in.line(), name, in.Peek());
    }
    double value = 0.0;
    SH_RETURN_IF_ERROR(ParseDouble(token, name, in.line(), &value));
    if (m->count >= kMaxMatrixEntries) {
      return Status::Error(StatusCode::kInvalidArgument,
                           "line %d: %s: more than %d numbers in data", in.line(), name,
                           kMaxMatrixEntries);
    }
    m->data[m->count++] = value;
    in.SkipSpaceAcrossLines();
    if (in.Consume(']')) return in.FinishLine();
    if (in.AtEnd()) {
      return Status::Error(StatusCode::kInvalidArgument, "line %d: %s: data list not closed by ']'",
                           in.line(), name);
    }
    if (!in.Consume(',')) {
      return Status::Error(StatusCode::kInvalidArgument,
                           "line %d: %s: expected ',' or ']' in data list", in.line(), name);
    }
  }
}

// Reads the indented block after "name: !!opencv-matrix".
Status ParseMatrixBlock(Reader& in, const char* name, ParsedMatrix* m) {
  bool has_rows = false, has_cols = false, has_dt = false, has_data = false;
  while (true) {
    in.SkipBlankLines();
    if (in.AtEnd() || in.Indent() == 0) break;
    char key[16];
    SH_RETURN_IF_ERROR(in.ReadKey(key, sizeof(key)));
    const int line = in.line();
    if (std::strcmp(key, "rows") == 0 || std::strcmp(key, "cols") == 0) {
      const bool is_rows = key[0] == 'r';
      bool& seen = is_rows ? has_rows : has_cols;
      if (seen) {
        return Status::Error(StatusCode::kInvalidArgument, "line %d: %s: duplicate '%s'", line,
                             name, key);
      }
      seen = true;
      char token[kMaxTokenChars];
      SH_RETURN_IF_ERROR(in.ReadToken(token, sizeof(token)));
      int value = 0;
      SH_RETURN_IF_ERROR(ParseInt(token, name, line, &value));
      if (value < 1 || value > kMaxMatrixDim) {
        return Status::Error(StatusCode::kInvalidArgument, "line %d: %s: %s = %d outside 1..%d",
                             line, name, key, value, kMaxMatrixDim);
      }
      (is_rows ? m->rows : m->cols) = value;
      SH_RETURN_IF_ERROR(in.FinishLine());
    } else if (std::strcmp(key, "dt") == 0) {
      if (has_dt) {
        return Status::Error(StatusCode::kInvalidArgument, "line %d: %s: duplicate 'dt'", line,
                             name);
      }
      has_dt = true;
      char token[kMaxTokenChars];
      SH_RETURN_IF_ERROR(in.ReadToken(token, sizeof(token)));
      if (std::strcmp(token, "d") != 0 && std::strcmp(token, "f") != 0) {
        return Status::Error(StatusCode::kInvalidArgument,
                             "line %d: %s: element type dt '%s' not supported (d or f)", line, name,
                             token);
      }
      SH_RETURN_IF_ERROR(in.FinishLine());
    } else if (std::strcmp(key, "data") == 0) {
      if (has_data) {
        return Status::Error(StatusCode::kInvalidArgument, "line %d: %s: duplicate 'data'", line,
                             name);
      }
      has_data = true;
      SH_RETURN_IF_ERROR(ParseMatrixData(in, name, m));
    } else {
      return Status::Error(StatusCode::kInvalidArgument,
                           "line %d: %s: unexpected matrix field '%s'", line, name, key);
    }
  }
  const char* missing = !has_rows   ? "rows"
                        : !has_cols ? "cols"
                        : !has_dt   ? "dt"
                        : !has_data ? "data"
                                    : nullptr;
  if (missing != nullptr) {
    return Status::Error(StatusCode::kInvalidArgument, "line %d: %s: matrix without '%s'", m->line,
                         name, missing);
  }
  if (m->count != m->rows * m->cols) {
    return Status::Error(StatusCode::kInvalidArgument,
                         "line %d: %s: data has %d numbers but rows x cols = %d x %d", m->line,
                         name, m->count, m->rows, m->cols);
  }
  return Status::Ok();
}

int SlotOf(const char* key) {
  if (!std::strcmp(key, "K1") || !std::strcmp(key, "M1")) return kK1;
  if (!std::strcmp(key, "D1")) return kD1;
  if (!std::strcmp(key, "K2") || !std::strcmp(key, "M2")) return kK2;
  if (!std::strcmp(key, "D2")) return kD2;
  if (!std::strcmp(key, "R")) return kR;
  if (!std::strcmp(key, "T")) return kT;
  return -1;
}

const char* CanonicalName(int slot) {
  static const char* const kNames[kMatrixSlots] = {"K1' (or 'M1", "D1", "K2' (or 'M2",
                                                   "D2",          "R",  "T"};
  return kNames[slot];
}

Status ParseTopLevel(Reader& in, ParsedFile* file) {
  // OpenCV writes "%YAML:1.0"; "%YAML 1.0" is the standard spelling; both are accepted.
  if (!in.StartsWith("%YAML:1.") && !in.StartsWith("%YAML 1.")) {
    return Status::Error(StatusCode::kInvalidArgument,
                         "not an OpenCV YAML file: first line must be '%%YAML:1.0'");
  }
  SH_RETURN_IF_ERROR(in.SkipValue());
  in.SkipBlankLines();
  if (in.StartsWith("---")) SH_RETURN_IF_ERROR(in.SkipValue());

  while (true) {
    in.SkipBlankLines();
    if (in.AtEnd() || in.StartsWith("...")) break;
    if (in.Indent() != 0) {
      return Status::Error(StatusCode::kInvalidArgument, "line %d: unexpected indentation",
                           in.line());
    }
    char key[64];
    SH_RETURN_IF_ERROR(in.ReadKey(key, sizeof(key)));
    const int line = in.line();
    const bool is_width = std::strcmp(key, "image_width") == 0;
    const bool is_height = std::strcmp(key, "image_height") == 0;
    const int slot = SlotOf(key);
    if (is_width || is_height) {
      bool& seen = is_width ? file->has_width : file->has_height;
      if (seen) {
        return Status::Error(StatusCode::kInvalidArgument, "line %d: duplicate key '%s'", line,
                             key);
      }
      seen = true;
      char token[kMaxTokenChars];
      SH_RETURN_IF_ERROR(in.ReadToken(token, sizeof(token)));
      SH_RETURN_IF_ERROR(ParseInt(token, key, line, is_width ? &file->width : &file->height));
      SH_RETURN_IF_ERROR(in.FinishLine());
    } else if (slot >= 0) {
      ParsedMatrix& m = file->matrices[slot];
      if (m.present) {
        return Status::Error(StatusCode::kInvalidArgument,
                             "line %d: '%s' duplicates '%s' from line %d", line, key,
                             file->names[slot], m.line);
      }
      m.present = true;
      m.line = line;
      file->names[slot] = slot == kK1   ? (key[0] == 'K' ? "K1" : "M1")
                          : slot == kK2 ? (key[0] == 'K' ? "K2" : "M2")
                                        : CanonicalName(slot);
      char token[kMaxTokenChars];
      SH_RETURN_IF_ERROR(in.ReadToken(token, sizeof(token)));
      if (std::strcmp(token, "!!opencv-matrix") != 0) {
        return Status::Error(StatusCode::kInvalidArgument,
                             "line %d: %s must be a '!!opencv-matrix', got '%s'", line, key, token);
      }
      SH_RETURN_IF_ERROR(in.FinishLine());
      SH_RETURN_IF_ERROR(ParseMatrixBlock(in, file->names[slot], &m));
    } else {
      // Unknown key: skip its value and any indented block under it.
      SH_RETURN_IF_ERROR(in.SkipValue());
      while (true) {
        in.SkipBlankLines();
        if (in.AtEnd() || in.Indent() == 0) break;
        SH_RETURN_IF_ERROR(in.SkipValue());
      }
    }
  }
  return Status::Ok();
}

Status ToIntrinsics(const ParsedMatrix& K, const char* k_name, const ParsedMatrix& D,
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

// Appends printf output to out[*used..capacity); false when it does not fit.
bool Append(char* out, size_t capacity, size_t* used, const char* fmt, ...)
    __attribute__((format(printf, 4, 5)));
bool Append(char* out, size_t capacity, size_t* used, const char* fmt, ...) {
  if (*used >= capacity) return false;
  va_list args;
  va_start(args, fmt);
  const int n = std::vsnprintf(out + *used, capacity - *used, fmt, args);
  va_end(args);
  if (n < 0 || static_cast<size_t>(n) >= capacity - *used) return false;
  *used += static_cast<size_t>(n);
  return true;
}

// A double as OpenCV's reader expects a real: 17 significant digits (exact round trip) and a
// '.' or exponent so that it is not taken for an integer.
void FormatReal(double v, char (&buf)[40]) {
  std::snprintf(buf, sizeof(buf), "%.17g", v);
  if (std::strpbrk(buf, ".eE") == nullptr)
    std::strncat(buf, ".", sizeof(buf) - std::strlen(buf) - 1);
}

bool AppendMatrix(char* out, size_t capacity, size_t* used, const char* name, int rows, int cols,
                  const double* data) {
  if (!Append(out, capacity, used,
              "%s: !!opencv-matrix\n   rows: %d\n   cols: %d\n   dt: d\n   data: [ ", name, rows,
              cols)) {
    return false;
  }
  const int n = rows * cols;
  for (int i = 0; i < n; ++i) {
    char number[40];
    FormatReal(data[i], number);
    const char* separator = i + 1 == n ? " ]\n" : (i % 4 == 3 ? ",\n       " : ", ");
    if (!Append(out, capacity, used, "%s%s", number, separator)) return false;
  }
  return true;
}

}  // namespace

Result<StereoCalibration> ParseCalibrationYaml(const char* text, size_t length) {
  if (text == nullptr || length == 0) {
    return Status::Error(StatusCode::kInvalidArgument, "calibration file is empty");
  }
  if (length > kMaxCalibrationYamlBytes) {
    return Status::Error(StatusCode::kOutOfRange,
                         "calibration file has %zu bytes, more than the %zu supported", length,
                         kMaxCalibrationYamlBytes);
  }
  if (std::memchr(text, '\0', length) != nullptr) {
    return Status::Error(StatusCode::kInvalidArgument,
                         "calibration file contains a NUL byte: not a text file");
  }
  ParsedFile file;
  Reader in(text, length);
  SH_RETURN_IF_ERROR(ParseTopLevel(in, &file));

  if (!file.has_width)
    return Status::Error(StatusCode::kInvalidArgument, "missing key 'image_width'");
  if (!file.has_height)
    return Status::Error(StatusCode::kInvalidArgument, "missing key 'image_height'");
  for (int slot = 0; slot < kMatrixSlots; ++slot) {
    if (!file.matrices[slot].present) {
      return Status::Error(StatusCode::kInvalidArgument, "missing key '%s'", CanonicalName(slot));
    }
  }

  StereoCalibration calib;
  SH_RETURN_IF_ERROR(ToIntrinsics(file.matrices[kK1], file.names[kK1], file.matrices[kD1], "D1",
                                  file.width, file.height, &calib.left));
  SH_RETURN_IF_ERROR(ToIntrinsics(file.matrices[kK2], file.names[kK2], file.matrices[kD2], "D2",
                                  file.width, file.height, &calib.right));
  const ParsedMatrix& R = file.matrices[kR];
  if (R.rows != 3 || R.cols != 3) {
    return Status::Error(StatusCode::kInvalidArgument, "R must be 3x3, got %dx%d", R.rows, R.cols);
  }
  const ParsedMatrix& T = file.matrices[kT];
  if (T.count != 3 || (T.rows != 1 && T.cols != 1)) {
    return Status::Error(StatusCode::kInvalidArgument, "T must be 3x1 or 1x3, got %dx%d", T.rows,
                         T.cols);
  }
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) calib.right_R_left(r, c) = R.data[r * 3 + c];  // row-major data
    calib.right_t_left_mm(r) = T.data[r];
  }
  SH_RETURN_IF_ERROR(ValidateStereoCalibration(calib));
  calib.right_R_left = NearestRotation(calib.right_R_left);
  return calib;
}

Result<size_t> WriteCalibrationYaml(const StereoCalibration& calib, char* out, size_t capacity) {
  SH_RETURN_IF_ERROR(ValidateStereoCalibration(calib));
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
  bool fits = Append(out, capacity, &used, "%%YAML:1.0\n---\nimage_width: %d\nimage_height: %d\n",
                     calib.left.width, calib.left.height);
  const CameraIntrinsics* cams[2] = {&calib.left, &calib.right};
  for (int i = 0; i < 2 && fits; ++i) {
    const CameraIntrinsics& c = *cams[i];
    const double K[9] = {c.fx, 0.0, c.cx, 0.0, c.fy, c.cy, 0.0, 0.0, 1.0};
    const double D[5] = {c.k1, c.k2, c.p1, c.p2, c.k3};
    fits = AppendMatrix(out, capacity, &used, i == 0 ? "K1" : "K2", 3, 3, K) &&
           AppendMatrix(out, capacity, &used, i == 0 ? "D1" : "D2", 1, 5, D);
  }
  double R[9];
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) R[r * 3 + c] = calib.right_R_left(r, c);
  }
  const double T[3] = {calib.right_t_left_mm.x(), calib.right_t_left_mm.y(),
                       calib.right_t_left_mm.z()};
  fits = fits && AppendMatrix(out, capacity, &used, "R", 3, 3, R) &&
         AppendMatrix(out, capacity, &used, "T", 3, 1, T);
  if (!fits) {
    out[0] = '\0';
    return Status::Error(StatusCode::kResourceExhausted,
                         "calibration YAML does not fit the %zu-byte output buffer", capacity);
  }
  return used;
}

}  // namespace sh
