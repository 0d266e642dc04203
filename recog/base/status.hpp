// Status and Result: recoverable errors without exceptions.
//
// A Status carries a code and a short human-readable message held inline (no heap), so it can be
// returned from the per-frame path. Asserts are reserved for broken invariants; anything caused
// by input (files, frames, commands) is reported through Status. As in Pigweed's pw_result, a
// Result holds a value or a non-ok Status: building one from an ok Status, or taking the value of
// one that failed, is a programming error and stops the program (SH_CHECK, in every build type).
#pragma once

#include <cstdarg>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <utility>

// A broken invariant: reported and fatal in every build type (unlike assert).
#define SH_CHECK(condition, what)                                            \
  do {                                                                       \
    if (!(condition)) ::sh::internal::CheckFailed(__FILE__, __LINE__, what); \
  } while (0)

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

  // The same code with "<prefix>: " before the message (printf-style prefix), for passing an
  // error up with what it concerned ("calib.yaml: line 3: ..."). An ok Status stays ok.
  Status WithContext(const char* fmt, ...) const __attribute__((format(printf, 2, 3)));

  bool ok() const { return code_ == StatusCode::kOk; }
  StatusCode code() const { return code_; }
  const char* message() const { return message_; }

 private:
  StatusCode code_ = StatusCode::kOk;
  char message_[kMaxMessage] = {};
};

namespace internal {
// Reports a broken invariant (file:line and what) on stderr and aborts.
[[noreturn]] void CheckFailed(const char* file, int line, const char* what);
}  // namespace internal

// Result<T>: either a value or a non-ok Status. Storage is inline.
template <typename T>
class [[nodiscard]] Result {
 public:
  Result(T value) : value_(std::move(value)) {}  // NOLINT: implicit by design
  Result(Status status) : status_(status) {      // NOLINT: implicit by design
    SH_CHECK(!status_.ok(), "Result built from an ok Status (it needs a value)");
  }

  bool ok() const { return value_.has_value(); }
  // The error; Status::Ok() when the Result holds a value.
  const Status& status() const { return status_; }
  T& value() {
    SH_CHECK(ok(), status_.message());
    return *value_;
  }
  const T& value() const {
    SH_CHECK(ok(), status_.message());
    return *value_;
  }
  T* operator->() { return &value(); }
  const T* operator->() const { return &value(); }
  T& operator*() { return value(); }
  const T& operator*() const { return value(); }

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

// `SH_ASSIGN_OR_RETURN(lhs, expr)`: evaluates expr (a Result<T>); on error returns its Status from
// the enclosing function, else moves the value into lhs (a declaration or an lvalue):
//   SH_ASSIGN_OR_RETURN(TableView view, TableView::Open(blob, size));
#define SH_ASSIGN_OR_RETURN(lhs, expr) \
  SH_ASSIGN_OR_RETURN_IMPL(SH_STATUS_CONCAT(sh_result_, __LINE__), lhs, expr)
// lhs is a declaration or an lvalue and result a name: neither can take parentheses.
// NOLINTBEGIN(bugprone-macro-parentheses)
#define SH_ASSIGN_OR_RETURN_IMPL(result, lhs, expr) \
  auto result = (expr);                             \
  if (!result.ok()) return result.status();         \
  lhs = std::move(result.value())
// NOLINTEND(bugprone-macro-parentheses)
#define SH_STATUS_CONCAT(a, b) SH_STATUS_CONCAT_INNER(a, b)
#define SH_STATUS_CONCAT_INNER(a, b) a##b
