// Reading a whole text input (a configuration, a scenario, a CSV table) with a size limit.
//
// A path can name something that never ends (/dev/zero, /dev/urandom, a FIFO fed forever) or a
// file far larger than any real input; reading it "until the end" takes the machine's memory.
// read_text_file stops after max_bytes + 1 bytes and refuses the input as too large, so such a
// path costs at most max_bytes of memory and a few milliseconds.
#pragma once

#include <cstddef>
#include <string>
#include <string_view>

#include "gfins/status/status.hpp"

namespace gfins::drivers::lnx {

/// Limits of the project's text inputs (each far above any real file of its kind).
inline constexpr std::size_t kMaxConfigBytes = 1u << 20;  // firmware configuration, scenarios
inline constexpr std::size_t kMaxTableBytes = 16u << 20;  // CSV tables (means, rate-table plans)

/// Reads the file at `path` into `out` (replaced). Errors: kIoError with errno when it cannot be
/// opened or read (a folder reads as EISDIR), kOutOfRange "larger than the limit" when it holds
/// more than max_bytes. `out` is left empty on error. The caller names the path in its message
/// (strerror of os_error() for the I/O errors).
Status read_text_file(const char* path, std::size_t max_bytes, std::string& out);

/// The one-line message of a read_text_file error: "<path>: cannot open the file: No such file
/// or directory (errno 2)", or "<path>: larger than <max_bytes> bytes, the limit for <what> (...)".
std::string text_file_error(std::string_view path, const Status& status, std::size_t max_bytes,
                            std::string_view what);

}  // namespace gfins::drivers::lnx
