#include "recog/camera/opencv_yaml.hpp"

#include <strings.h>

#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <cstdlib>
#include <cstring>

namespace sh {
namespace {

constexpr int kMaxMatrixDim = 16;
// Longest number token; OpenCV writes at most ~24 characters ("-2.6637260909660682e-01").
constexpr size_t kMaxTokenChars = 48;

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

Status ParseMatrixData(Reader& in, const char* name, YamlMatrix* m) {
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
    if (m->count >= kMaxYamlMatrixEntries) {
      return Status::Error(StatusCode::kInvalidArgument,
                           "line %d: %s: more than %d numbers in data", in.line(), name,
                           kMaxYamlMatrixEntries);
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
Status ParseMatrixBlock(Reader& in, const char* name, YamlMatrix* m) {
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

YamlKey* FindKey(YamlKey* keys, size_t n_keys, const char* key) {
  for (size_t i = 0; i < n_keys; ++i) {
    if (std::strcmp(key, keys[i].name) == 0) return &keys[i];
    if (keys[i].alias != nullptr && std::strcmp(key, keys[i].alias) == 0) return &keys[i];
  }
  return nullptr;
}

Status ParseTopLevel(Reader& in, YamlKey* keys, size_t n_keys) {
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
    YamlKey* wanted = FindKey(keys, n_keys, key);
    if (wanted == nullptr) {
      // Unknown key: skip its value and any indented block under it.
      SH_RETURN_IF_ERROR(in.SkipValue());
      while (true) {
        in.SkipBlankLines();
        if (in.AtEnd() || in.Indent() == 0) break;
        SH_RETURN_IF_ERROR(in.SkipValue());
      }
      continue;
    }
    const bool seen = wanted->integer ? wanted->integer->present : wanted->matrix->present;
    if (seen) {
      const int first = wanted->integer ? wanted->integer->line : wanted->matrix->line;
      return Status::Error(StatusCode::kInvalidArgument,
                           "line %d: '%s' duplicates '%s' from line %d", line, key, wanted->name,
                           first);
    }
    const char* spelling = std::strcmp(key, wanted->name) == 0 ? wanted->name : wanted->alias;
    if (wanted->spelling != nullptr) *wanted->spelling = spelling;
    char token[kMaxTokenChars];
    SH_RETURN_IF_ERROR(in.ReadToken(token, sizeof(token)));
    if (wanted->integer != nullptr) {
      YamlInt& v = *wanted->integer;
      v.present = true;
      v.line = line;
      SH_RETURN_IF_ERROR(ParseInt(token, spelling, line, &v.value));
      SH_RETURN_IF_ERROR(in.FinishLine());
    } else {
      YamlMatrix& m = *wanted->matrix;
      m.present = true;
      m.line = line;
      if (std::strcmp(token, "!!opencv-matrix") != 0) {
        return Status::Error(StatusCode::kInvalidArgument,
                             "line %d: %s must be a '!!opencv-matrix', got '%s'", line, spelling,
                             token);
      }
      SH_RETURN_IF_ERROR(in.FinishLine());
      SH_RETURN_IF_ERROR(ParseMatrixBlock(in, spelling, &m));
    }
  }
  return Status::Ok();
}

// A double as OpenCV's reader expects a real: 17 significant digits (exact round trip) and a
// '.' or exponent so that it is not taken for an integer.
void FormatReal(double v, char (&buf)[40]) {
  std::snprintf(buf, sizeof(buf), "%.17g", v);
  if (std::strpbrk(buf, ".eE") == nullptr)
    std::strncat(buf, ".", sizeof(buf) - std::strlen(buf) - 1);
}

}  // namespace

Status ReadOpenCvYaml(const char* text, size_t length, size_t max_bytes, const char* what,
                      YamlKey* keys, size_t n_keys) {
  if (text == nullptr || length == 0) {
    return Status::Error(StatusCode::kInvalidArgument, "%s is empty", what);
  }
  if (length > max_bytes) {
    return Status::Error(StatusCode::kOutOfRange, "%s has %zu bytes, more than the %zu supported",
                         what, length, max_bytes);
  }
  if (std::memchr(text, '\0', length) != nullptr) {
    return Status::Error(StatusCode::kInvalidArgument, "%s contains a NUL byte: not a text file",
                         what);
  }
  Reader in(text, length);
  return ParseTopLevel(in, keys, n_keys);
}

bool YamlAppend(char* out, size_t capacity, size_t* used, const char* fmt, ...) {
  if (*used >= capacity) return false;
  va_list args;
  va_start(args, fmt);
  const int n = std::vsnprintf(out + *used, capacity - *used, fmt, args);
  va_end(args);
  if (n < 0 || static_cast<size_t>(n) >= capacity - *used) return false;
  *used += static_cast<size_t>(n);
  return true;
}

bool YamlAppendMatrix(char* out, size_t capacity, size_t* used, const char* name, int rows,
                      int cols, const double* data) {
  if (!YamlAppend(out, capacity, used,
                  "%s: !!opencv-matrix\n   rows: %d\n   cols: %d\n   dt: d\n   data: [ ", name,
                  rows, cols)) {
    return false;
  }
  const int n = rows * cols;
  for (int i = 0; i < n; ++i) {
    char number[40];
    FormatReal(data[i], number);
    const char* separator = i + 1 == n ? " ]\n" : (i % 4 == 3 ? ",\n       " : ", ");
    if (!YamlAppend(out, capacity, used, "%s%s", number, separator)) return false;
  }
  return true;
}

}  // namespace sh
