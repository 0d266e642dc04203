// A small JSON reader for the truth files of recorded scenes and the tests of the tools' JSON
// output: objects, arrays, strings
// (without escapes beyond \" \\ \/ \n \t), numbers, true, false, null. Malformed input gives a
// null value and ok == false.
#pragma once

#include <cstdlib>
#include <map>
#include <memory>
#include <string>
#include <vector>

namespace sh {

struct Json {
  enum Type { kNull, kBool, kNumber, kString, kArray, kObject } type = kNull;
  bool boolean = false;
  double number = 0;
  std::string text;
  std::vector<Json> items;
  std::map<std::string, Json> members;

  const Json& operator[](const std::string& key) const {
    static const Json null;
    auto it = members.find(key);
    return it == members.end() ? null : it->second;
  }
  const Json& operator[](size_t i) const {
    static const Json null;
    return i < items.size() ? items[i] : null;
  }
  size_t size() const { return type == kArray ? items.size() : members.size(); }
};

class JsonReader {
 public:
  explicit JsonReader(const std::string& s) : s_(s) {}

  bool Parse(Json* out) {
    ok_ = true;
    pos_ = 0;
    *out = Value();
    Space();
    return ok_ && pos_ == s_.size();
  }

 private:
  void Space() {
    while (pos_ < s_.size() &&
           (s_[pos_] == ' ' || s_[pos_] == '\n' || s_[pos_] == '\r' || s_[pos_] == '\t')) {
      ++pos_;
    }
  }
  bool Eat(char c) {
    Space();
    if (pos_ < s_.size() && s_[pos_] == c) {
      ++pos_;
      return true;
    }
    return false;
  }
  bool Word(const char* w) {
    const std::string word(w);
    if (s_.compare(pos_, word.size(), word) != 0) return false;
    pos_ += word.size();
    return true;
  }
  std::string String() {
    std::string r;
    if (!Eat('"')) {
      ok_ = false;
      return r;
    }
    while (pos_ < s_.size() && s_[pos_] != '"') {
      char c = s_[pos_++];
      if (c == '\\' && pos_ < s_.size()) {
        const char e = s_[pos_++];
        c = e == 'n' ? '\n' : e == 't' ? '\t' : e;
      }
      r += c;
    }
    if (pos_ >= s_.size()) ok_ = false;
    ++pos_;
    return r;
  }
  Json Value() {
    Json v;
    Space();
    if (pos_ >= s_.size() || depth_ > 64) {
      ok_ = false;
      return v;
    }
    const char c = s_[pos_];
    if (c == '{') {
      ++pos_;
      ++depth_;
      v.type = Json::kObject;
      if (!Eat('}')) {
        do {
          const std::string key = String();
          if (!Eat(':')) ok_ = false;
          v.members[key] = Value();
        } while (ok_ && Eat(','));
        if (!Eat('}')) ok_ = false;
      }
      --depth_;
    } else if (c == '[') {
      ++pos_;
      ++depth_;
      v.type = Json::kArray;
      if (!Eat(']')) {
        do {
          v.items.push_back(Value());
        } while (ok_ && Eat(','));
        if (!Eat(']')) ok_ = false;
      }
      --depth_;
    } else if (c == '"') {
      v.type = Json::kString;
      v.text = String();
    } else if (Word("true")) {
      v.type = Json::kBool;
      v.boolean = true;
    } else if (Word("false")) {
      v.type = Json::kBool;
    } else if (Word("null")) {
    } else {
      char* end = nullptr;
      v.number = std::strtod(s_.c_str() + pos_, &end);
      if (end == s_.c_str() + pos_) ok_ = false;
      pos_ = static_cast<size_t>(end - s_.c_str());
      v.type = Json::kNumber;
    }
    return v;
  }

  const std::string& s_;
  size_t pos_ = 0;
  int depth_ = 0;
  bool ok_ = true;
};

}  // namespace sh
