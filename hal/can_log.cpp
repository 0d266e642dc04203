#include "hal/can_log.hpp"

#include <cinttypes>
#include <cstdlib>
#include <cstring>

namespace sh::hal {
namespace {

// SocketCAN marks error frames with this bit in can_id (linux/can.h CAN_ERR_FLAG); repeated here
// so the formatter builds on hosts without CAN headers.
constexpr uint32_t kCanErrFlag = 0x20000000u;
constexpr char kHex[] = "0123456789ABCDEF";

int HexValue(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

}  // namespace

size_t FormatCandumpLine(const CanFrame& frame, const char* interface, char* out, size_t capacity) {
  if (frame.len > kCanMaxDataBytes || out == nullptr || capacity == 0) return 0;
  const uint64_t sec = frame.timestamp_us / 1000000u;
  const uint64_t usec = frame.timestamp_us % 1000000u;
  int n;
  if (frame.error) {
    n = std::snprintf(out, capacity, "(%" PRIu64 ".%06" PRIu64 ") %s %08X#", sec, usec, interface,
                      (frame.id | kCanErrFlag) & 0x3FFFFFFFu);
  } else if (frame.extended) {
    n = std::snprintf(out, capacity, "(%" PRIu64 ".%06" PRIu64 ") %s %08X#", sec, usec, interface,
                      frame.id & kCanExtendedIdMax);
  } else {
    n = std::snprintf(out, capacity, "(%" PRIu64 ".%06" PRIu64 ") %s %03X#", sec, usec, interface,
                      frame.id & kCanStandardIdMax);
  }
  if (n < 0 || static_cast<size_t>(n) >= capacity) return 0;
  size_t pos = static_cast<size_t>(n);
  // Room needed for the payload: 2 hex digits per byte (or "R" + DLC digit), '\n' and '\0'.
  const size_t payload = frame.rtr ? 2 : 2u * frame.len;
  if (pos + payload + 2 > capacity) return 0;
  if (frame.rtr) {
    out[pos++] = 'R';
    if (frame.len != 0) out[pos++] = kHex[frame.len];
  } else {
    for (uint8_t i = 0; i < frame.len; ++i) {
      out[pos++] = kHex[frame.data[i] >> 4];
      out[pos++] = kHex[frame.data[i] & 0xF];
    }
  }
  out[pos++] = '\n';
  out[pos] = '\0';
  return pos;
}

Status ParseCandumpLine(const char* line, CanFrame* frame, char* interface_out,
                        size_t interface_capacity) {
  if (line == nullptr || frame == nullptr) {
    return Status::Error(StatusCode::kInvalidArgument, "candump line: null argument");
  }
  CanFrame f;
  const char* p = line;
  if (*p != '(') {
    return Status::Error(StatusCode::kInvalidArgument, "candump line must start with '(': '%.40s'",
                         line);
  }
  ++p;
  char* end = nullptr;
  const unsigned long long sec = std::strtoull(p, &end, 10);
  if (end == p || *end != '.') {
    return Status::Error(StatusCode::kInvalidArgument, "candump line: bad timestamp in '%.40s'",
                         line);
  }
  p = end + 1;
  const char* usec_start = p;
  const unsigned long long usec = std::strtoull(p, &end, 10);
  if (end - usec_start != 6 || *end != ')') {
    return Status::Error(StatusCode::kInvalidArgument,
                         "candump line: timestamp needs 6 fractional digits: '%.40s'", line);
  }
  f.timestamp_us = sec * 1000000ull + usec;
  p = end + 1;
  if (*p != ' ') {
    return Status::Error(StatusCode::kInvalidArgument, "candump line: no interface in '%.40s'",
                         line);
  }
  ++p;
  const char* if_start = p;
  while (*p != '\0' && *p != ' ') ++p;
  const size_t if_len = static_cast<size_t>(p - if_start);
  if (if_len == 0 || *p != ' ') {
    return Status::Error(StatusCode::kInvalidArgument, "candump line: no frame in '%.40s'", line);
  }
  if (interface_out != nullptr && interface_capacity > 0) {
    const size_t copy = if_len < interface_capacity - 1 ? if_len : interface_capacity - 1;
    std::memcpy(interface_out, if_start, copy);
    interface_out[copy] = '\0';
  }
  ++p;
  const char* id_start = p;
  uint32_t id = 0;
  while (HexValue(*p) >= 0) {
    if (p - id_start >= 8) break;
    id = (id << 4) | static_cast<uint32_t>(HexValue(*p));
    ++p;
  }
  const size_t id_digits = static_cast<size_t>(p - id_start);
  if (*p != '#' || (id_digits != 3 && id_digits != 8)) {
    return Status::Error(StatusCode::kInvalidArgument,
                         "candump line: id must be 3 or 8 hex digits followed by '#': '%.40s'",
                         line);
  }
  ++p;
  if (id_digits == 8) {
    if (id & kCanErrFlag) {
      f.error = true;
      f.id = id & ~kCanErrFlag;
    } else {
      f.extended = true;
      f.id = id;
    }
  } else {
    f.id = id;
  }
  if (f.id > (f.extended || f.error ? kCanExtendedIdMax : kCanStandardIdMax)) {
    return Status::Error(StatusCode::kInvalidArgument, "candump line: id 0x%X out of range", f.id);
  }
  if (*p == 'R') {
    f.rtr = true;
    ++p;
    const int dlc = HexValue(*p);
    if (dlc >= 0) {
      if (dlc > kCanMaxDataBytes) {
        return Status::Error(StatusCode::kInvalidArgument, "candump line: RTR length %d > 8", dlc);
      }
      f.len = static_cast<uint8_t>(dlc);
      ++p;
    }
  } else {
    while (HexValue(p[0]) >= 0) {
      if (HexValue(p[1]) < 0) {
        return Status::Error(StatusCode::kInvalidArgument,
                             "candump line: odd number of data digits in '%.40s'", line);
      }
      if (f.len == kCanMaxDataBytes) {
        return Status::Error(StatusCode::kInvalidArgument,
                             "candump line: more than 8 data bytes in '%.40s'", line);
      }
      f.data[f.len++] = static_cast<uint8_t>(HexValue(p[0]) << 4 | HexValue(p[1]));
      p += 2;
    }
  }
  if (*p != '\0' && *p != '\n' && *p != '\r' && *p != ' ') {
    return Status::Error(StatusCode::kInvalidArgument,
                         "candump line: unexpected character '%c' in '%.40s'", *p, line);
  }
  *frame = f;
  return Status::Ok();
}

void CandumpLogger::Log(const CanFrame& frame) {
  char line[kCandumpLineMax];
  const size_t n = FormatCandumpLine(frame, bus_->name(), line, sizeof(line));
  if (n == 0 || std::fwrite(line, 1, n, out_) != n) {
    write_errors_.fetch_add(1);
    return;
  }
  if (flush_each_line_) std::fflush(out_);
}

Status CandumpLogger::Send(const CanFrame& frame) {
  CanFrame stamped = frame;
  if (stamped.timestamp_us == 0) stamped.timestamp_us = CanNowUs();
  SH_RETURN_IF_ERROR(bus_->Send(stamped));
  Log(stamped);
  return Status::Ok();
}

Result<bool> CandumpLogger::Receive(CanFrame* frame, int timeout_ms) {
  Result<bool> got = bus_->Receive(frame, timeout_ms);
  if (got.ok() && *got) Log(*frame);
  return got;
}

}  // namespace sh::hal
