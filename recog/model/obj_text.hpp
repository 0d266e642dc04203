// Tokenising of OBJ and MTL text. The text is not NUL-terminated, so every read is bounded by
// `end`; numbers are parsed without the C library (strtod needs a NUL terminator and depends on
// the locale).
#pragma once

#include <cstddef>

namespace sh::obj {

inline bool IsSpace(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f'; }
inline bool IsDigit(char c) { return c >= '0' && c <= '9'; }

inline void SkipSpaces(const char*& p, const char* end) {
  while (p < end && IsSpace(*p)) ++p;
}

inline bool AtTokenEnd(const char* p, const char* end) { return p == end || IsSpace(*p); }

// Parses a decimal floating-point number ([+-]digits[.digits][(e|E)[+-]digits]), skipping
// leading spaces; on kMalformed / kNonFinite the token is skipped.
enum class NumberError { kNone, kMissing, kMalformed, kNonFinite };
NumberError ParseDouble(const char*& p, const char* end, double* value);

// One face vertex reference "v", "v/vt", "v/vt/vn" or "v//vn" (spaces skipped first). Indices
// are as written (1-based, negative counts back); 0 means absent (vt, vn). kMissing at the end
// of the line, kMalformed for anything else that is not such a token.
NumberError ParseFaceVertex(const char*& p, const char* end, long* v, long* vt);

// The lines of an OBJ or MTL text, each split into its keyword and the rest:
//   for (LineReader r(text, len); r.Next();) if (r.Is("v")) Parse(r.rest, r.end) ...
class LineReader {
 public:
  LineReader(const char* text, size_t len) : p_(text), text_end_(text + len) {}
  // Moves to the next line; false after the last.
  bool Next();
  bool Is(const char* word) const;

  int line = 0;                // 1-based number of the current line
  const char* rest = nullptr;  // after the keyword (parsers advance it)
  const char* end = nullptr;   // end of the line (its '\n', '\r' or the end of the text)

 private:
  const char* p_;
  const char* text_end_;
  const char* keyword_ = nullptr;
  size_t keyword_len_ = 0;
};

// Resolves a 1-based or negative OBJ index against `count` defined items: the 0-based index, or
// -1 when it refers to nothing.
long ResolveObjIndex(long index, long count);

}  // namespace sh::obj
