// Errors as values for every layer of gfins (nav_core, hal, drivers, firmware).
//
// The vocabulary lives beside nav_core because it is the one piece every layer shares and it
// depends on nothing but the standard library: no heap, no exceptions, no OS. A Status carries a
// code and a message that must point to storage with static lifetime (a string literal), so it
// can be copied and returned from an interrupt-free sample loop without allocating.
#pragma once

#include <cstdint>
#include <type_traits>
#include <utility>

namespace gfins {

enum class ErrorCode : std::uint8_t {
  kOk = 0,
  kInvalidArgument,     // caller passed a value outside the documented domain
  kFailedPrecondition,  // object not in a state where the call makes sense (not initialised)
  kOutOfRange,          // index or value outside a buffer or a physical range
  kSingular,            // a matrix that must be inverted is singular or ill-conditioned
  kDataLoss,            // corrupt or truncated data (CRC, checksum, short file)
  kUnavailable,         // a device or interface is missing or not answering
  kIoError,             // an OS call failed (errno is in the message context)
  kTimeout,             // a wait expired
  kResourceExhausted,   // a fixed-capacity buffer is full
  kUnimplemented,
};

/// Human-readable name of a code ("invalid argument", ...).
constexpr const char* to_string(ErrorCode code) {
  switch (code) {
    case ErrorCode::kOk:
      return "ok";
    case ErrorCode::kInvalidArgument:
      return "invalid argument";
    case ErrorCode::kFailedPrecondition:
      return "failed precondition";
    case ErrorCode::kOutOfRange:
      return "out of range";
    case ErrorCode::kSingular:
      return "singular";
    case ErrorCode::kDataLoss:
      return "data loss";
    case ErrorCode::kUnavailable:
      return "unavailable";
    case ErrorCode::kIoError:
      return "i/o error";
    case ErrorCode::kTimeout:
      return "timeout";
    case ErrorCode::kResourceExhausted:
      return "resource exhausted";
    case ErrorCode::kUnimplemented:
      return "unimplemented";
  }
  return "unknown";
}

class [[nodiscard]] Status {
 public:
  constexpr Status() = default;
  /// `message` must have static storage duration (a literal).
  constexpr Status(ErrorCode code, const char* message) : code_(code), message_(message) {}
  /// Same, with the operating system's error number (errno) of the call that failed, for the
  /// Linux backends; 0 means none.
  constexpr Status(ErrorCode code, const char* message, int os_error)
      : code_(code), message_(message), os_error_(os_error) {}

  static constexpr Status ok() { return Status(); }

  constexpr bool is_ok() const { return code_ == ErrorCode::kOk; }
  constexpr ErrorCode code() const { return code_; }
  constexpr const char* message() const { return message_; }
  /// errno of the failed OS call (0 when the error did not come from the OS).
  constexpr int os_error() const { return os_error_; }

  friend constexpr bool operator==(const Status& a, const Status& b) { return a.code_ == b.code_; }

 private:
  ErrorCode code_ = ErrorCode::kOk;
  const char* message_ = "";
  int os_error_ = 0;
};

/// A value or the Status explaining why there is none. T must be default-constructible; no
/// heap is used (the value is stored in place).
template <typename T>
class [[nodiscard]] Result {
  static_assert(std::is_default_constructible_v<T>, "Result<T> stores T in place");

 public:
  constexpr Result(const T& value) : value_(value) {}        // NOLINT: implicit on purpose
  constexpr Result(T&& value) : value_(std::move(value)) {}  // NOLINT: implicit on purpose
  // An ok Status carries no value, so building a Result from one is a programming error that is
  // reported rather than hidden.
  constexpr Result(Status status)  // NOLINT: implicit on purpose
      : status_(status.is_ok() ? Status(ErrorCode::kFailedPrecondition,
                                        "Result built from an ok Status without a value")
                               : status) {}

  constexpr bool is_ok() const { return status_.is_ok(); }
  constexpr Status status() const { return status_; }
  constexpr const T& value() const& { return value_; }
  constexpr T& value() & { return value_; }
  constexpr T&& value() && { return std::move(value_); }
  constexpr const T& operator*() const& { return value_; }
  constexpr const T* operator->() const { return &value_; }
  constexpr T* operator->() { return &value_; }

 private:
  T value_{};
  Status status_{};
};

}  // namespace gfins
