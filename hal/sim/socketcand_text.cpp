#include "hal/sim/socketcand_text.hpp"

#include <cinttypes>
#include <cstdio>
#include <cstring>

namespace sh::hal {
namespace {

constexpr char kHexLower[] = "0123456789abcdef";
constexpr size_t kMaxTokens = 12;  // "send", id, len, 8 bytes, plus one to detect extras

int HexValue(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

bool IsBlank(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\n'; }

struct Token {
  const char* text;
  size_t length;
};

bool TokenIs(const Token& t, const char* word) {
  return t.length == std::strlen(word) && std::memcmp(t.text, word, t.length) == 0;
}

// Parses 1..max_digits hex digits.
bool ParseHex(const Token& t, size_t max_digits, uint32_t* value) {
  if (t.length == 0 || t.length > max_digits) return false;
  uint32_t v = 0;
  for (size_t i = 0; i < t.length; ++i) {
    const int h = HexValue(t.text[i]);
    if (h < 0) return false;
    v = (v << 4) | static_cast<uint32_t>(h);
  }
  *value = v;
  return true;
}

}  // namespace

size_t FormatSocketcandFrame(const CanFrame& frame, char* out, size_t capacity) {
  if (frame.len > kCanMaxDataBytes || out == nullptr) return 0;
  char data[2 * kCanMaxDataBytes + 1];
  for (uint8_t i = 0; i < frame.len; ++i) {
    data[2 * i] = kHexLower[frame.data[i] >> 4];
    data[2 * i + 1] = kHexLower[frame.data[i] & 0xF];
  }
  data[2 * frame.len] = '\0';
  // An empty payload gives "< frame 181 1.000000  >", which socketcand itself sends and
  // python-can parses as a zero-length frame.
  const int n = std::snprintf(out, capacity, "< frame %X %" PRIu64 ".%06" PRIu64 " %s >", frame.id,
                              frame.timestamp_us / 1000000u, frame.timestamp_us % 1000000u, data);
  if (n < 0 || static_cast<size_t>(n) >= capacity) return 0;
  return static_cast<size_t>(n);
}

Status ParseSocketcandCommand(const char* text, size_t length, SocketcandCommand* out) {
  if (length < 2 || text[0] != '<' || text[length - 1] != '>') {
    return Status::Error(StatusCode::kInvalidArgument, "message is not enclosed in '< >'");
  }
  Token tokens[kMaxTokens];
  size_t count = 0;
  size_t i = 1;
  while (i < length - 1) {
    while (i < length - 1 && IsBlank(text[i])) ++i;
    if (i >= length - 1) break;
    const size_t start = i;
    while (i < length - 1 && !IsBlank(text[i])) ++i;
    if (count == kMaxTokens) {
      return Status::Error(StatusCode::kInvalidArgument, "too many fields (more than %zu)",
                           kMaxTokens - 1);
    }
    tokens[count++] = {text + start, i - start};
  }
  if (count == 0) return Status::Error(StatusCode::kInvalidArgument, "empty message '< >'");

  SocketcandCommand cmd;
  const Token& word = tokens[0];
  if (TokenIs(word, "open")) {
    if (count != 2 || tokens[1].length >= kSocketcandArgumentMax) {
      return Status::Error(StatusCode::kInvalidArgument, "'open' needs one bus name");
    }
    cmd.kind = SocketcandCommandKind::kOpen;
    std::memcpy(cmd.argument, tokens[1].text, tokens[1].length);
  } else if (TokenIs(word, "rawmode")) {
    cmd.kind = SocketcandCommandKind::kRawMode;
  } else if (TokenIs(word, "echo")) {
    cmd.kind = SocketcandCommandKind::kEcho;
  } else if (TokenIs(word, "send")) {
    if (count < 3) {
      return Status::Error(StatusCode::kInvalidArgument, "'send' needs an id and a length");
    }
    uint32_t id = 0;
    if (!ParseHex(tokens[1], 8, &id) || id > kCanExtendedIdMax) {
      return Status::Error(StatusCode::kInvalidArgument,
                           "'send' id '%.*s' is not a hex CAN id (1..8 digits, <= 1FFFFFFF)",
                           static_cast<int>(tokens[1].length < 16 ? tokens[1].length : 16),
                           tokens[1].text);
    }
    uint32_t len = 0;
    if (!ParseHex(tokens[2], 2, &len) || len > kCanMaxDataBytes) {
      return Status::Error(StatusCode::kInvalidArgument, "'send' length '%.*s' is not 0..8",
                           static_cast<int>(tokens[2].length < 16 ? tokens[2].length : 16),
                           tokens[2].text);
    }
    if (count - 3 != len) {
      return Status::Error(StatusCode::kInvalidArgument,
                           "'send' announces %u data bytes but carries %zu", len, count - 3);
    }
    cmd.kind = SocketcandCommandKind::kSend;
    cmd.frame.id = id;
    cmd.frame.extended = tokens[1].length == 8 || id > kCanStandardIdMax;
    cmd.frame.len = static_cast<uint8_t>(len);
    for (uint32_t b = 0; b < len; ++b) {
      uint32_t v = 0;
      if (!ParseHex(tokens[3 + b], 2, &v)) {
        return Status::Error(
            StatusCode::kInvalidArgument, "'send' data byte %u '%.*s' is not 1-2 hex digits", b,
            static_cast<int>(tokens[3 + b].length < 16 ? tokens[3 + b].length : 16),
            tokens[3 + b].text);
      }
      cmd.frame.data[b] = static_cast<uint8_t>(v);
    }
  } else {
    cmd.kind = SocketcandCommandKind::kOther;
    const size_t n =
        word.length < kSocketcandArgumentMax - 1 ? word.length : kSocketcandArgumentMax - 1;
    std::memcpy(cmd.argument, word.text, n);
  }
  *out = cmd;
  return Status::Ok();
}

SocketcandScan ScanSocketcandMessage(const char* buffer, size_t length) {
  SocketcandScan scan;
  size_t pos = 0;
  while (pos < length) {
    // Skip to the next '<'; anything non-blank on the way is garbage.
    size_t open = pos;
    while (open < length && buffer[open] != '<') {
      if (!IsBlank(buffer[open])) scan.skipped_garbage = true;
      ++open;
    }
    if (open == length) {
      scan.consumed = length;
      return scan;
    }
    size_t close = open + 1;
    while (close < length && buffer[close] != '>' && buffer[close] != '<') ++close;
    if (close < length && buffer[close] == '<') {
      // A new message starts before this one closed: drop the fragment.
      scan.skipped_garbage = true;
      pos = close;
      continue;
    }
    if (close == length) {
      if (length - open > kSocketcandMessageMax) {
        scan.skipped_garbage = true;
        scan.consumed = length;
      } else {
        scan.consumed = open;
      }
      return scan;
    }
    if (close + 1 - open > kSocketcandMessageMax) {
      scan.skipped_garbage = true;
      pos = close + 1;
      continue;
    }
    scan.have_message = true;
    scan.message_begin = open;
    scan.message_length = close + 1 - open;
    scan.consumed = close + 1;
    return scan;
  }
  scan.consumed = length;
  return scan;
}

}  // namespace sh::hal
