// Output views of gfins-can decode: a refreshing terminal table of the latest epoch, one line
// per epoch, CSV, JSON lines.
#pragma once

#include <chrono>
#include <cstdio>
#include <memory>
#include <string>

#include "decoder.hpp"

namespace gfins::can_tool {

class View {
 public:
  virtual ~View() = default;
  virtual void epoch(const DecodedEpoch& e) = 0;
  /// A GNSS fix or heading from the aiding input frames (line and json views print them; csv
  /// and table keep to the epochs' columns).
  virtual void input(const DecodedInput&) {}
  virtual void finish() {}
};

enum class ViewKind { kTable, kLine, kCsv, kJson, kNone };

/// `out` stays owned by the caller. Throws std::invalid_argument for an unknown name.
ViewKind parse_view(const std::string& name);
std::unique_ptr<View> make_view(ViewKind kind, std::FILE* out);

/// Text of a value for the views: "" for NaN (not available / absent), else %.10g.
std::string format_value(double v);

}  // namespace gfins::can_tool
