// Parameter store seam: where the calibration file lives (a file on the board's filesystem on
// Linux; memory in tests). Loads and saves whole blobs; save is atomic: after a crash or power
// loss at any instant the store holds either the old or the new content, never a mixture.
#pragma once

#include <cstddef>
#include <span>

#include "gfins/status/status.hpp"

namespace gfins::hal {

class ParameterStore {
 public:
  /// Largest blob a store must hold (a calibration file is a few kB of TOML).
  static constexpr std::size_t kMaxBytes = std::size_t{64} * 1024;

  virtual ~ParameterStore() = default;

  /// Copies the stored blob into `buffer`; returns its size. kUnavailable when nothing is
  /// stored; kResourceExhausted when it does not fit in `buffer`; kIoError from the backend.
  [[nodiscard]] Result<std::size_t> load(std::span<char> buffer) {
    if (buffer.empty()) return Status(ErrorCode::kInvalidArgument, "parameter store: empty buffer");
    return do_load(buffer);
  }

  /// Replaces the stored blob atomically. kInvalidArgument when larger than kMaxBytes.
  [[nodiscard]] Status save(std::span<const char> blob) {
    if (blob.size() > kMaxBytes) {
      return Status(ErrorCode::kInvalidArgument, "parameter store: blob larger than kMaxBytes");
    }
    return do_save(blob);
  }

 private:
  virtual Result<std::size_t> do_load(std::span<char> buffer) = 0;
  virtual Status do_save(std::span<const char> blob) = 0;
};

}  // namespace gfins::hal
