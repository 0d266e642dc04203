// A JSON text built in order (objects, arrays, keys, values) with the escaping done here, for
// the page's API answers.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

namespace sh::fw::web {

class JsonWriter {
 public:
  JsonWriter& BeginObject();
  JsonWriter& EndObject();
  JsonWriter& BeginArray();
  JsonWriter& EndArray();
  JsonWriter& Key(const char* key);
  JsonWriter& String(const char* text);
  JsonWriter& String(const char* text, size_t bytes);
  JsonWriter& Int(long long value);
  JsonWriter& Uint(unsigned long long value);
  JsonWriter& Number(double value, int digits = 6);  // non-finite numbers are written as null
  JsonWriter& Bool(bool value);
  JsonWriter& Null();

  const std::string& text() const { return text_; }

 private:
  void Separate();  // the comma before a value or key that follows another
  std::string text_;
  bool need_comma_ = false;
};

// `text` as a JSON string (quotes, backslash, control characters escaped; bytes of 0x80 and
// above passed through only as valid UTF-8, else \ufffd).
void AppendJsonString(std::string* out, const char* text, size_t bytes);

}  // namespace sh::fw::web
