// Status and Result: recoverable errors without exceptions.
//
// A Status carries a code and a short human-readable message held inline (no heap), so it can be
// returned from the per-frame path. Asserts are reserved for broken invariants; anything caused
// by input (files, frames, commands) is reported through Status.
#pragma once

#include <cstdarg>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <utility>

namespace sh {

enum class StatusCode : uint8_t {
  kOk = 0,
  kInvalidArgument,     // malformed input: bad file contents, out-of-range command
  kOutOfRange,          // value outside the supported range
  kDataLoss,            // truncated or corrupted data (CRC mismatch, short read)
  kNotFound,            // missing file, model or device
  kResourceExhausted,   // a compile-time capacity was reached
  kUnavailable,         // device or peer not available (camera stopped, bus off)
  kDeadlineExceeded,    // time budget or timeout ran out
  kFailedPrecondition,  // called in the wrong state
  kUnimplemented,       // not supported in this build or on this kernel
  kInternal,            // invariant broken in a way we could still report
};

const char* StatusCodeName(StatusCode code);

class [[nodiscard]] Status {
 public:
  static constexpr size_t kMaxMessage = 160;

  constexpr Status() = default;
  static Status Ok() { return Status(); }
  // printf-style message; truncated to kMaxMessage - 1 characters.
  static Status Error(StatusCode code, const char* fmt, ...) __attribute__((format(printf, 2, 3)));

  bool ok() const { return code_ == StatusCode::kOk; }
  StatusCode code() const { return code_; }
  const char* message() const { return message_; }

 private:
  StatusCode code_ = StatusCode::kOk;
  char message_[kMaxMessage] = {};
};

// Result<T>: either a value or a non-ok Status. Storage is inline.
template <typename T>
class [[nodiscard]] Result {
 public:
  Result(T value) : value_(std::move(value)) {}  // NOLINT: implicit by design
  Result(Status status) : status_(status) {}     // NOLINT: implicit by design

  bool ok() const { return value_.has_value(); }
  const Status& status() const { return status_; }
  T& value() { return *value_; }
  const T& value() const { return *value_; }
  T* operator->() { return &*value_; }
  const T* operator->() const { return &*value_; }
  T& operator*() { return *value_; }
  const T& operator*() const { return *value_; }

 private:
  Status status_;
  std::optional<T> value_;
};

}  // namespace sh

// Propagate a non-ok Status to the caller.
#define SH_RETURN_IF_ERROR(expr)             \
  do {                                       \
    ::sh::Status sh_status_ = (expr);        \
    if (!sh_status_.ok()) return sh_status_; \
  } while (0)
