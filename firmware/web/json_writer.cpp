#include "firmware/web/json_writer.hpp"

#include <cmath>
#include <cstdio>
#include <cstring>

namespace sh::fw::web {
namespace {

// Length of the UTF-8 sequence at p (at most `left` bytes), or 0 if it is not a valid one.
size_t Utf8Length(const unsigned char* p, size_t left) {
  size_t n = 0;
  if (p[0] >= 0xC2 && p[0] <= 0xDF) {
    n = 2;
  } else if (p[0] >= 0xE0 && p[0] <= 0xEF) {
    n = 3;
  } else if (p[0] >= 0xF0 && p[0] <= 0xF4) {
    n = 4;
  } else {
    return 0;
  }
  if (n > left) return 0;
  for (size_t i = 1; i < n; ++i) {
    if ((p[i] & 0xC0) != 0x80) return 0;
  }
  return n;
}

}  // namespace

void AppendJsonString(std::string* out, const char* text, size_t bytes) {
  out->push_back('"');
  const auto* p = reinterpret_cast<const unsigned char*>(text);
  for (size_t i = 0; i < bytes;) {
    const unsigned char c = p[i];
    if (c == '"' || c == '\\') {
      out->push_back('\\');
      out->push_back(static_cast<char>(c));
    } else if (c == '\n') {
      out->append("\\n");
    } else if (c < 0x20 || c == 0x7F) {
      char esc[8];
      std::snprintf(esc, sizeof(esc), "\\u%04x", c);
      out->append(esc);
    } else if (c >= 0x80) {
      const size_t n = Utf8Length(p + i, bytes - i);
      if (n == 0) {
        out->append("\\ufffd");
        ++i;
        continue;
      }
      out->append(text + i, n);
      i += n;
      continue;
    } else {
      out->push_back(static_cast<char>(c));
    }
    ++i;
  }
  out->push_back('"');
}

void JsonWriter::Separate() {
  if (need_comma_) text_.push_back(',');
  need_comma_ = true;
}

JsonWriter& JsonWriter::BeginObject() {
  Separate();
  text_.push_back('{');
  need_comma_ = false;
  return *this;
}

JsonWriter& JsonWriter::EndObject() {
  text_.push_back('}');
  need_comma_ = true;
  return *this;
}

JsonWriter& JsonWriter::BeginArray() {
  Separate();
  text_.push_back('[');
  need_comma_ = false;
  return *this;
}

JsonWriter& JsonWriter::EndArray() {
  text_.push_back(']');
  need_comma_ = true;
  return *this;
}

JsonWriter& JsonWriter::Key(const char* key) {
  Separate();
  AppendJsonString(&text_, key, std::strlen(key));
  text_.push_back(':');
  need_comma_ = false;  // the value follows without a comma
  return *this;
}

JsonWriter& JsonWriter::String(const char* text) { return String(text, std::strlen(text)); }

JsonWriter& JsonWriter::String(const char* text, size_t bytes) {
  Separate();
  AppendJsonString(&text_, text, bytes);
  return *this;
}

JsonWriter& JsonWriter::Int(long long value) {
  Separate();
  text_.append(std::to_string(value));
  return *this;
}

JsonWriter& JsonWriter::Uint(unsigned long long value) {
  Separate();
  text_.append(std::to_string(value));
  return *this;
}

JsonWriter& JsonWriter::Number(double value, int digits) {
  Separate();
  if (!std::isfinite(value)) {
    text_.append("null");
    return *this;
  }
  char buf[40];
  std::snprintf(buf, sizeof(buf), "%.*g", digits, value);
  text_.append(buf);
  return *this;
}

JsonWriter& JsonWriter::Bool(bool value) {
  Separate();
  text_.append(value ? "true" : "false");
  return *this;
}

JsonWriter& JsonWriter::Null() {
  Separate();
  text_.append("null");
  return *this;
}

}  // namespace sh::fw::web
