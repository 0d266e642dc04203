#include "recog/base/printable.hpp"

#include <cstdio>
#include <cstring>

namespace sh {
namespace {

constexpr size_t kPieceBytes = 8;

// The printable form of one byte; returns its length.
size_t Escape(unsigned char byte, char piece[kPieceBytes]) {
  if (byte == '\\') {
    std::memcpy(piece, "\\\\", 3);
  } else if (byte >= 0x20 && byte < 0x7F) {
    piece[0] = static_cast<char>(byte);
    piece[1] = '\0';
  } else {
    std::snprintf(piece, kPieceBytes, "\\x%02X", byte);
  }
  return std::strlen(piece);
}

// The form of one byte inside a JSON string literal; returns its length.
size_t EscapeJson(unsigned char byte, char piece[kPieceBytes]) {
  if (byte == '\\' || byte == '"') {
    piece[0] = '\\';
    piece[1] = static_cast<char>(byte);
    piece[2] = '\0';
  } else if (byte >= 0x20 && byte < 0x7F) {
    piece[0] = static_cast<char>(byte);
    piece[1] = '\0';
  } else {
    std::snprintf(piece, kPieceBytes, "\\u%04x", byte);
  }
  return std::strlen(piece);
}

const char* EscapeAll(const char* raw, size_t raw_length, char* out, size_t out_size,
                      size_t (*escape)(unsigned char, char*)) {
  static constexpr char kEllipsis[] = "...";
  if (out_size == 0) return out;
  size_t length = 0;
  while (length < raw_length && raw[length] != '\0') ++length;
  size_t escaped = 0;
  char piece[kPieceBytes];
  for (size_t i = 0; i < length; ++i) escaped += escape(static_cast<unsigned char>(raw[i]), piece);
  // Everything fits: all of it; else as many whole pieces as leave room for the ellipsis.
  // A buffer too small for the ellipsis gets the text cut short without it.
  const bool mark = escaped + 1 > out_size && out_size > sizeof(kEllipsis);
  const size_t room = mark ? out_size - sizeof(kEllipsis) : out_size - 1;
  size_t n = 0;
  for (size_t i = 0; i < length; ++i) {
    const size_t len = escape(static_cast<unsigned char>(raw[i]), piece);
    if (n + len > room) break;
    std::memcpy(out + n, piece, len);
    n += len;
  }
  out[n] = '\0';
  if (mark) std::memcpy(out + n, kEllipsis, sizeof(kEllipsis));
  return out;
}

}  // namespace

const char* Printable(const char* raw, size_t raw_length, char* out, size_t out_size) {
  return EscapeAll(raw, raw_length, out, out_size, Escape);
}

const char* JsonEscaped(const char* raw, size_t raw_length, char* out, size_t out_size) {
  return EscapeAll(raw, raw_length, out, out_size, EscapeJson);
}

}  // namespace sh
