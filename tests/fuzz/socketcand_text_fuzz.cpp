// libFuzzer target: the socketcand text protocol as the server reads it. Arbitrary bytes go
// through the receive-buffer scanner in the pieces a TCP stream might deliver, every message it
// finds through the command parser; a parsed "send" must be a valid CAN frame whose "frame"
// message the scanner finds again whole. Nothing may crash or read outside the buffers.
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>

#include "hal/sim/socketcand_text.hpp"

namespace {

constexpr size_t kBufferBytes = 1024;  // as the server's input buffer

void CheckSend(const sh::hal::SocketcandCommand& cmd) {
  if (!sh::hal::ValidateCanFrame(cmd.frame).ok()) std::abort();
  char text[sh::hal::kSocketcandMessageMax + 1];
  const size_t n = sh::hal::FormatSocketcandFrame(cmd.frame, text, sizeof(text));
  if (n == 0) std::abort();
  const sh::hal::SocketcandScan scan = sh::hal::ScanSocketcandMessage(text, n);
  if (!scan.have_message || scan.message_begin != 0 || scan.message_length != n) std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  // The first byte picks the piece size the stream arrives in (1..64 bytes).
  const size_t piece = size > 0 ? 1 + data[0] % 64 : 1;
  char buffer[kBufferBytes];
  size_t used = 0;
  for (size_t at = size > 0 ? 1 : 0; at < size;) {
    const size_t take = std::min({piece, size - at, kBufferBytes - used});
    std::memcpy(buffer + used, data + at, take);
    used += take;
    at += take;
    for (;;) {
      const sh::hal::SocketcandScan scan = sh::hal::ScanSocketcandMessage(buffer, used);
      if (scan.consumed > used) std::abort();
      if (scan.have_message) {
        if (scan.message_begin + scan.message_length > used) std::abort();
        sh::hal::SocketcandCommand cmd;
        const sh::Status s =
            sh::hal::ParseSocketcandCommand(buffer + scan.message_begin, scan.message_length, &cmd);
        if (s.ok() && cmd.kind == sh::hal::SocketcandCommandKind::kSend) CheckSend(cmd);
      }
      std::memmove(buffer, buffer + scan.consumed, used - scan.consumed);
      used -= scan.consumed;
      if (!scan.have_message) break;
    }
    // A full buffer without a complete message is what the scanner must never leave.
    if (used == kBufferBytes) std::abort();
  }
  return 0;
}
