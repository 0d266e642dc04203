// candump log format ("candump -l" / "-L"), usable with any CanBus backend:
//   (1700000000.000001) can0 181#0102030405060708
// Extended ids print as 8 hex digits, remote frames as "123#R" (plus the DLC digit if non-zero),
// error frames as the 8-digit id with CAN_ERR_FLAG (0x20000000) set. Files in this format replay
// with can-utils' canplayer and load in python-can (can.CanutilsLogReader).
#pragma once

#include <atomic>
#include <cstdio>

#include "hal/can.hpp"

namespace sh::hal {

// Longest line: "(" 20-digit sec "." 6 digits ") " 15-char ifname " " 8-digit id "#" 16 hex
// digits, newline and terminator, rounded up.
inline constexpr size_t kCandumpLineMax = 96;

// Writes one line (with a trailing '\n') into out. Returns the number of characters written, or
// 0 if capacity is too small or the frame is invalid (len > 8).
size_t FormatCandumpLine(const CanFrame& frame, const char* interface, char* out, size_t capacity);

// Parses one line (trailing newline optional). The interface name is copied into
// interface_out (at most interface_capacity - 1 characters) if it is non-null.
Status ParseCandumpLine(const char* line, CanFrame* frame, char* interface_out,
                        size_t interface_capacity);

// A CanBus decorator that appends every frame sent through it and every frame received from it
// to a candump log. The file is owned by the caller and must outlive the logger.
class CandumpLogger final : public CanBus {
 public:
  // flush_each_line: fflush after every line so that a crash loses nothing (costs a syscall).
  CandumpLogger(CanBus* bus, FILE* out, bool flush_each_line = false)
      : bus_(bus), out_(out), flush_each_line_(flush_each_line) {}

  Status Send(const CanFrame& frame) override;
  Result<bool> Receive(CanFrame* frame, int timeout_ms) override;
  CanStats stats() const override { return bus_->stats(); }
  CanBusState state() const override { return bus_->state(); }
  const char* name() const override { return bus_->name(); }

  // Lines that could not be written (short write on the log file).
  uint64_t write_errors() const { return write_errors_.load(); }

 private:
  void Log(const CanFrame& frame);

  CanBus* bus_;
  FILE* out_;
  bool flush_each_line_;
  std::atomic<uint64_t> write_errors_{0};  // Send() and Receive() may run on two threads
};

}  // namespace sh::hal
