// Text of the socketcand protocol (https://github.com/linux-can/socketcand, doc/protocol.md) as
// far as the simulator needs it: the handshake, raw mode frames and "send" commands.
// Pure functions on caller buffers, so the server's parsing can be tested without sockets.
#pragma once

#include <cstddef>
#include <cstdint>

#include "hal/can.hpp"

namespace sh::hal {

// Longest message we accept from a client ("< send 1FFFFFFF 8 ff ff ff ff ff ff ff ff >" is 45).
inline constexpr size_t kSocketcandMessageMax = 128;
inline constexpr size_t kSocketcandArgumentMax = 24;

// "< frame 181 1700000000.000001 0102030405060708 >": id in upper-case hex without padding,
// timestamp seconds.microseconds, data as one contiguous hex string (python-can splits the
// message on spaces and keeps only the first data token). Returns the length written (no
// terminator counted), 0 if it does not fit.
size_t FormatSocketcandFrame(const CanFrame& frame, char* out, size_t capacity);

enum class SocketcandCommandKind : uint8_t { kOpen, kRawMode, kSend, kEcho, kOther };

struct SocketcandCommand {
  SocketcandCommandKind kind = SocketcandCommandKind::kOther;
  char argument[kSocketcandArgumentMax] = {};  // bus name for kOpen, command word for kOther
  CanFrame frame;                              // kSend
};

// Parses one complete message "< word args... >". Errors name the problem (kInvalidArgument).
// "< send ID LEN B0 .. >": ID hex (8 digits or > 0x7FF = extended), LEN 0..8, LEN bytes in hex
// with 1 or 2 digits each (python-can sends them unpadded).
Status ParseSocketcandCommand(const char* text, size_t length, SocketcandCommand* out);

// Finds the next message in a receive buffer.
struct SocketcandScan {
  bool have_message = false;
  size_t message_begin = 0;      // index of '<'
  size_t message_length = 0;     // through '>'
  size_t consumed = 0;           // bytes the caller may drop from the front of the buffer
  bool skipped_garbage = false;  // non-blank bytes outside "< ... >" were dropped
};
// Without a complete message, `consumed` covers only garbage before the next '<' (or all of a
// buffer without '<'); an unterminated message longer than kSocketcandMessageMax is garbage.
SocketcandScan ScanSocketcandMessage(const char* buffer, size_t length);

}  // namespace sh::hal
