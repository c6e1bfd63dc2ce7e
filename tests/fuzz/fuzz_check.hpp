// Shared by the libFuzzer targets of this folder (docs/reliability.md): an invariant that does
// not hold is a finding like a crash, so it prints what broke and aborts (libFuzzer saves the
// input as a crash artifact and the ctest fails).
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <span>
#include <string_view>

namespace gfins::fuzz {

[[noreturn]] inline void fail(const char* target, const char* what) {
  std::fprintf(stderr, "fuzz %s: invariant broken: %s\n", target, what);
  std::abort();
}

inline void check(bool ok, const char* target, const char* what) {
  if (!ok) fail(target, what);
}

/// Reads the fuzzer's bytes front to back; past the end it yields zeros (so a harness never
/// reads outside the input and short inputs are still valid).
class Bytes {
 public:
  Bytes(const std::uint8_t* data, std::size_t size) : data_(data, size) {}
  bool empty() const { return pos_ >= data_.size(); }
  std::size_t left() const { return empty() ? 0 : data_.size() - pos_; }
  std::uint8_t u8() { return empty() ? 0 : data_[pos_++]; }
  std::uint32_t u32() {
    std::uint32_t v = 0;
    for (int i = 0; i < 4; ++i) v |= static_cast<std::uint32_t>(u8()) << (8 * i);
    return v;
  }
  /// Fills `out` with the next bytes (zeros past the end).
  void fill(std::span<std::uint8_t> out) {
    for (std::uint8_t& b : out) b = u8();
  }
  /// The rest of the input as text.
  std::string_view rest_text() {
    if (empty()) return {};
    const auto* p = reinterpret_cast<const char*>(data_.data() + pos_);
    const std::size_t n = data_.size() - pos_;
    pos_ = data_.size();
    return {p, n};
  }

 private:
  std::span<const std::uint8_t> data_;
  std::size_t pos_ = 0;
};

inline std::string_view as_text(const std::uint8_t* data, std::size_t size) {
  return {reinterpret_cast<const char*>(data), size};
}

}  // namespace gfins::fuzz

namespace gfins::fuzz {

/// A message for a terminal: no control character but newline and tab (a file's bytes quoted in
/// an error must come escaped, or a hostile file could drive the user's terminal).
inline bool printable_message(std::string_view m) {
  for (const char ch : m) {
    const auto c = static_cast<unsigned char>(ch);
    if ((c < 0x20 && c != '\n' && c != '\t') || c == 0x7F) return false;
  }
  return true;
}

}  // namespace gfins::fuzz
