#include "recog/model/obj_text.hpp"

#include <cmath>
#include <cstring>

namespace sh::obj {

NumberError ParseDouble(const char*& p, const char* end, double* value) {
  SkipSpaces(p, end);
  if (p == end) return NumberError::kMissing;
  const char* start = p;
  bool negative = false;
  if (*p == '+' || *p == '-') negative = *p++ == '-';
  if (p < end && (*p == 'n' || *p == 'N' || *p == 'i' || *p == 'I')) {
    while (p < end && !IsSpace(*p)) ++p;
    return NumberError::kNonFinite;
  }
  double mantissa = 0;
  int exponent10 = 0;
  int digits = 0;
  while (p < end && IsDigit(*p)) {
    mantissa = mantissa * 10 + (*p++ - '0');
    ++digits;
  }
  if (p < end && *p == '.') {
    ++p;
    while (p < end && IsDigit(*p)) {
      mantissa = mantissa * 10 + (*p++ - '0');
      --exponent10;
      ++digits;
    }
  }
  if (digits == 0) {
    p = start;
    while (p < end && !IsSpace(*p)) ++p;
    return NumberError::kMalformed;
  }
  if (p < end && (*p == 'e' || *p == 'E')) {
    ++p;
    bool exp_negative = false;
    if (p < end && (*p == '+' || *p == '-')) exp_negative = *p++ == '-';
    int e = 0;
    int exp_digits = 0;
    while (p < end && IsDigit(*p)) {
      if (e < 100000) e = e * 10 + (*p - '0');  // saturate: anything this big is non-finite
      ++p;
      ++exp_digits;
    }
    if (exp_digits == 0) return NumberError::kMalformed;
    exponent10 += exp_negative ? -e : e;
  }
  if (!AtTokenEnd(p, end)) return NumberError::kMalformed;
  const double v = mantissa * std::pow(10.0, exponent10);
  if (!std::isfinite(v)) return NumberError::kNonFinite;
  *value = negative ? -v : v;
  return NumberError::kNone;
}

namespace {

// An optionally signed integer, saturated at 10^6 (far beyond any capacity); false when there
// are no digits.
bool ParseSignedIndex(const char*& p, const char* end, long* value) {
  bool negative = false;
  if (p < end && (*p == '-' || *p == '+')) negative = *p++ == '-';
  long index = 0;
  int digits = 0;
  while (p < end && IsDigit(*p)) {
    if (index < 1000000) index = index * 10 + (*p - '0');
    ++p;
    ++digits;
  }
  *value = negative ? -index : index;
  return digits > 0;
}

}  // namespace

NumberError ParseFaceVertex(const char*& p, const char* end, long* v, long* vt) {
  SkipSpaces(p, end);
  if (p == end) return NumberError::kMissing;
  *v = 0;
  *vt = 0;
  if (!ParseSignedIndex(p, end, v)) {
    while (p < end && !IsSpace(*p)) ++p;
    return NumberError::kMalformed;
  }
  if (p < end && *p == '/') {
    ++p;
    if (p < end && *p != '/' && !IsSpace(*p) && !ParseSignedIndex(p, end, vt)) {
      while (p < end && !IsSpace(*p)) ++p;
      return NumberError::kMalformed;
    }
    if (p < end && *p == '/') {
      ++p;
      long vn = 0;
      if (!AtTokenEnd(p, end) && !ParseSignedIndex(p, end, &vn)) {
        while (p < end && !IsSpace(*p)) ++p;
        return NumberError::kMalformed;
      }
    }
  }
  if (!AtTokenEnd(p, end)) {
    while (p < end && !IsSpace(*p)) ++p;
    return NumberError::kMalformed;
  }
  return NumberError::kNone;
}

bool LineReader::Next() {
  if (p_ >= text_end_) return false;
  ++line;
  const char* line_end = p_;
  // "\n", "\r\n" and a lone "\r" (old Mac exports) each end a line.
  while (line_end < text_end_ && *line_end != '\n' && *line_end != '\r') ++line_end;
  const char* p = p_;
  SkipSpaces(p, line_end);
  keyword_ = p;
  while (p < line_end && !IsSpace(*p)) ++p;
  keyword_len_ = static_cast<size_t>(p - keyword_);
  rest = p;
  end = line_end;
  p_ = line_end < text_end_ ? line_end + 1 : text_end_;
  if (p_ < text_end_ && *line_end == '\r' && *p_ == '\n') ++p_;
  return true;
}

bool LineReader::Is(const char* word) const {
  return keyword_len_ == std::strlen(word) && std::memcmp(keyword_, word, keyword_len_) == 0;
}

long ResolveObjIndex(long index, long count) {
  const long resolved = index < 0 ? count + index : index - 1;
  return (index == 0 || resolved < 0 || resolved >= count) ? -1 : resolved;
}

}  // namespace sh::obj
