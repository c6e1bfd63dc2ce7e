// The one error type of the host side (host_sim library, gfins-sim, replay): a value, never an
// exception, with an owned message that names the file, key, line or byte offset concerned.
//
// nav_core, hal and drivers use gfins::Status / gfins::Result<T>, whose messages are literals
// (no heap). Host code builds messages with file names and values, so it needs owned strings:
// HostError is Status's code plus such a message; HostResult<T> is Result<T>'s host twin. The
// libraries below the host return Status; host_error(status, context) lifts one.
//
// Propagation is explicit and short with GFINS_TRY:
//
//   HostResult<Scenario> load(...) {
//     GFINS_TRY(auto text, read_text(path));      // returns the error to the caller, or binds
//     GFINS_TRY_STATUS(check(text));              // for HostResult<Done>
//     ...
//   }
//
// Exceptions are allowed in host tools but stop at this interface: a library function that
// calls a throwing API (tomlplusplus, std::filesystem overloads without error_code) catches and
// returns a HostError. The programs' main() turn a HostError into a message and an exit code.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <type_traits>
#include <utility>

#include "gfins/status/status.hpp"

namespace gfins::sim {

struct HostError {
  ErrorCode code = ErrorCode::kFailedPrecondition;
  std::string message;            // what is wrong, naming the file/key/line/offset concerned
  std::uint64_t byte_offset = 0;  // for errors about a file's bytes: where the problem starts
};

/// A Status from nav_core/hal/drivers with the host's context ("scenario x: ").
inline HostError host_error(const Status& st, const std::string& context) {
  return HostError{st.code(), context + st.message(), 0};
}

/// A refusal of the caller's input (a value, a file's content, an option), with what is wrong.
inline HostError invalid_argument(std::string message) {
  return HostError{ErrorCode::kInvalidArgument, std::move(message), 0};
}

/// Success without a value.
struct Done {};

/// A value or the HostError explaining why there is none.
template <typename T>
class [[nodiscard]] HostResult {
 public:
  HostResult(T value) : value_(std::move(value)) {}         // NOLINT: implicit on purpose
  HostResult(HostError error) : error_(std::move(error)) {  // NOLINT: implicit on purpose
    if (error_.code == ErrorCode::kOk) error_.code = ErrorCode::kFailedPrecondition;
  }

  bool is_ok() const { return value_.has_value(); }
  const T& value() const& { return *value_; }
  T& value() & { return *value_; }
  T&& value() && { return std::move(*value_); }
  const T* operator->() const { return &*value_; }
  T* operator->() { return &*value_; }
  const HostError& error() const { return error_; }
  HostError&& take_error() && { return std::move(error_); }

 private:
  std::optional<T> value_;
  HostError error_{};
};

using HostStatus = HostResult<Done>;

}  // namespace gfins::sim

#define GFINS_TRY_CONCAT_INNER(a, b) a##b
#define GFINS_TRY_CONCAT(a, b) GFINS_TRY_CONCAT_INNER(a, b)

/// `GFINS_TRY(decl, expr);`: evaluates expr (a HostResult); on error returns the error from the
/// enclosing function (whose return type must be constructible from HostError), else declares
/// `decl` from the value.
// `decl` is a declaration (`auto x`), which parentheses would break.
// NOLINTBEGIN(bugprone-macro-parentheses)
#define GFINS_TRY(decl, expr)                                              \
  auto GFINS_TRY_CONCAT(gfins_try_, __LINE__) = (expr);                    \
  if (!GFINS_TRY_CONCAT(gfins_try_, __LINE__).is_ok()) {                   \
    return std::move(GFINS_TRY_CONCAT(gfins_try_, __LINE__)).take_error(); \
  }                                                                        \
  decl = std::move(GFINS_TRY_CONCAT(gfins_try_, __LINE__)).value()
// NOLINTEND(bugprone-macro-parentheses)

/// `GFINS_TRY_STATUS(expr);`: the same for a result whose value is not needed.
#define GFINS_TRY_STATUS(expr)                          \
  do {                                                  \
    auto gfins_try_status_ = (expr);                    \
    if (!gfins_try_status_.is_ok()) {                   \
      return std::move(gfins_try_status_).take_error(); \
    }                                                   \
  } while (false)
